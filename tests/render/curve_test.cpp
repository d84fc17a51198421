// Curves render as tubes seen only from outside: they block what is behind
// them (camera and shadow rays), but a ray that starts inside one, as a
// hair BSDF's transmission does, leaves without meeting the far wall.
#include <gtest/gtest.h>

#include <algorithm>
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

// Hair fibres (pbrt-v4's hair BSDF on curve tubes) in a white furnace: with
// no absorption every fibre scatters all it receives, so every pixel sees
// the environment's radiance 1 however many fibres its paths cross. With
// eumelanin the same fibres are darker, and nothing is non-finite.
std::string hair_bundle(const std::string& material) {
  std::string s = R"(
LookAt 0 0 5  0 0 0  0 1 0
Camera "perspective" "float fov" [ 14 ]
Film "rgb" "integer xresolution" [ 24 ] "integer yresolution" [ 24 ]
Sampler "zsobol" "integer pixelsamples" [ 128 ]
Integrator "volpath" "integer maxdepth" [ 200 ]
WorldBegin
LightSource "infinite" "rgb L" [ 1 1 1 ]
)" + material + "\n";
  // Three layers of fibres 0.06 wide, 0.05 apart, bent in x and z.
  for (int layer = 0; layer < 3; ++layer)
    for (int i = 0; i < 12; ++i) {
      const double x = -0.6 + 0.1 * i + 0.033 * layer, z = -0.1 * layer;
      s += "Shape \"curve\" \"point3 P\" [ " + std::to_string(x) + " -1 " + std::to_string(z) + "  " +
           std::to_string(x + 0.05) + " -0.3 " + std::to_string(z + 0.05) + "  " + std::to_string(x - 0.05) + " 0.3 " +
           std::to_string(z - 0.05) + "  " + std::to_string(x) + " 1 " + std::to_string(z) +
           " ] \"float width\" 0.06 \"string type\" \"cylinder\"\n";
    }
  return s;
}

TEST(Curves, HairInAWhiteFurnaceReturnsWhatItReceives) {
  const ImageRgb white = film_mean(testing::render_text(hair_bundle("Material \"hair\" \"rgb sigma_a\" [ 0 0 0 ]")).film);
  double sum = 0.0, worst = 0.0;
  for (float v : white.rgb) {
    ASSERT_TRUE(std::isfinite(v));
    sum += v;
    worst = std::max(worst, std::fabs(v - 1.0));
  }
  EXPECT_NEAR(sum / white.rgb.size(), 1.0, 0.005);
  EXPECT_LT(worst, 0.25);  // per pixel, 128 samples
  const ImageRgb brown = film_mean(testing::render_text(hair_bundle("Material \"hair\" \"float eumelanin\" 1.3")).film);
  double covered = 0.0;
  for (size_t i = 0; i < brown.rgb.size(); ++i) {
    ASSERT_TRUE(std::isfinite(brown.rgb[i]));
    covered += brown.rgb[i] < 0.9f;
  }
  EXPECT_GT(covered / brown.rgb.size(), 0.5);  // the fibres cover most of the view
  EXPECT_LT(testing::image_mean(brown), 0.7);
}

}  // namespace
}  // namespace tessera
