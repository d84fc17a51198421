// A thindielectric window in front of an emitter: seen head-on, the emitter
// keeps 1 - R of its radiance (R = 0.0769 for eta 1.5, the interreflected
// share), unshifted and unscaled by eta^2, where a refracting dielectric
// surface would let 1 - 0.04 through, scaled by 1 / 1.5^2.
#include <gtest/gtest.h>

#include "render_helpers.h"

namespace tessera {
namespace {

TEST(ThinDielectric, AWindowPassesOneMinusItsReflectanceUndeflected) {
  const std::string scene = R"(
LookAt 0 0 0  0 0 1  0 1 0
Camera "perspective" "float fov" [ 2 ]
Film "rgb" "integer xresolution" [ 8 ] "integer yresolution" [ 8 ]
Sampler "independent" "integer pixelsamples" [ 256 ]
Integrator "path" "integer maxdepth" [ 5 ]
WorldBegin
AttributeBegin
AreaLightSource "diffuse" "rgb L" [ 1 1 1 ]
Material "diffuse" "rgb reflectance" [ 0 0 0 ]
Shape "trianglemesh" "point3 P" [ -100 -100 10  100 -100 10  100 100 10  -100 100 10 ] "integer indices" [ 0 2 1 0 3 2 ]
AttributeEnd
Material "thindielectric" "float eta" 1.5
Shape "trianglemesh" "point3 P" [ -50 -50 5  50 -50 5  50 50 5  -50 50 5 ] "integer indices" [ 0 2 1 0 3 2 ]
)";
  const double R1 = 0.04, R = R1 + (1 - R1) * (1 - R1) * R1 / (1 - R1 * R1);
  // The reflected share sees the camera's side: black. What comes through is
  // the emitter times 1 - R (a black emitter reflects nothing back).
  EXPECT_NEAR(testing::image_mean(film_mean(testing::render_text(scene).film)), 1.0 - R, 0.01);
}

}  // namespace
}  // namespace tessera
