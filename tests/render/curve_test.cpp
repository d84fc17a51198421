// Curves render as tubes seen only from outside: they block what is behind
// them (camera and shadow rays), but a ray that starts inside one, as a
// hair BSDF's transmission does, leaves without meeting the far wall.
#include <gtest/gtest.h>

#include <cmath>

#include "render_helpers.h"

namespace tessera {
namespace {

// A two-sided emitter (L = 1) at z = 10 fills the view of a camera at the
// origin looking down +z; black curves in between.
double seen(const std::string& curves, const std::string& camera = "LookAt 0 0 0  0 0 1  0 1 0\n") {
  const std::string scene = camera + R"(
Camera "perspective" "float fov" [ 20 ]
Film "rgb" "integer xresolution" [ 32 ] "integer yresolution" [ 32 ]
Sampler "independent" "integer pixelsamples" [ 64 ]
Integrator "path" "integer maxdepth" [ 1 ]
WorldBegin
AttributeBegin
AreaLightSource "diffuse" "rgb L" [ 1 1 1 ] "bool twosided" true
Shape "trianglemesh" "point3 P" [ -100 -100 10  100 -100 10  100 100 10  -100 100 10 ] "integer indices" [ 0 1 2 0 2 3 ]
AttributeEnd
Material "diffuse" "rgb reflectance" [ 0 0 0 ]
)" + curves;
  return testing::image_mean(film_mean(testing::render_text(scene).film));
}

const char* kWideTubeAlongX =
    "Shape \"curve\" \"point3 P\" [ -20 0 0  -5 0 0  5 0 0  20 0 0 ] \"string type\" \"cylinder\" \"float width\" 3\n";

TEST(Curves, BlockTheirWidthFromOutside) {
  EXPECT_NEAR(seen(""), 1.0, 1e-6);
  // At z = 5 the view is 2 * 5 * tan(10 deg) = 1.76 high; a tube of width
  // 0.5 across it hides 0.5 / 1.76 of it (its projection lies between 0.91
  // and 1.05 times the width, by the hexagon's turn about its axis).
  const double tube = seen("Translate 0 0 5\nShape \"curve\" \"point3 P\" [ -5 0 0  -1 0 0  1 0 0  5 0 0 ] "
                           "\"string type\" \"cylinder\" \"float width\" 0.5\n");
  const double band = 0.5 / (10.0 * std::tan(10.0 * M_PI / 180.0));
  EXPECT_GT(1.0 - tube, band * 0.9);
  EXPECT_LT(1.0 - tube, band * 1.06);
}

TEST(Curves, RaysFromInsideATubeLeaveIt) {
  // The camera at the origin sits inside a tube of width 3 along x: it sees
  // the emitter through the tube's far wall. A flat ribbon in its place
  // (two-sided) blocks the view.
  EXPECT_NEAR(seen(kWideTubeAlongX), 1.0, 1e-6);
  EXPECT_NEAR(seen("Translate 0 0 1\nShape \"curve\" \"point3 P\" [ -20 0 0  -5 0 0  5 0 0  20 0 0 ] "
                   "\"string type\" \"ribbon\" \"float width\" 3 \"normal N\" [ 0 0 1  0 0 1 ]\n"),
              0.0, 1e-6);
  // From outside, the same tube hides the emitter.
  EXPECT_NEAR(seen(kWideTubeAlongX, "LookAt 0 0 -5  0 0 1  0 1 0\n"), 0.0, 1e-6);
}

}  // namespace
}  // namespace tessera
