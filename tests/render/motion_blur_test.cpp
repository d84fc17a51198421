// Motion blur (pbrt-v4's ActiveTransform / TransformTimes): every camera ray
// gets a time in the shutter interval and sees moving shapes where they are
// then (vertices interpolated between the start and end transforms).
#include <gtest/gtest.h>

#include <string>

#include "render_helpers.h"

namespace tessera {
namespace {

// A white quad x in [-2, 0] at z = 10, lit head-on; `motion` (after
// ActiveTransform EndTime) moves its end position, `camera_motion` the
// camera's. The camera sees x in [-2, 2].
std::string quad_scene(const std::string& motion, const std::string& camera_params = "",
                       const std::string& camera_motion = "") {
  return R"(
LookAt 0 0 0  0 0 1  0 1 0
ActiveTransform EndTime
)" + camera_motion + R"(
ActiveTransform All
Camera "perspective" "float fov" [ 22.619865 ] )" + camera_params + R"(
Film "rgb" "integer xresolution" [ 32 ] "integer yresolution" [ 32 ]
Sampler "independent" "integer pixelsamples" [ 256 ]
Integrator "path" "integer maxdepth" [ 1 ]
PixelFilter "box"
WorldBegin
LightSource "distant" "point3 from" [ 0 0 0 ] "point3 to" [ 0 0 1 ] "rgb L" [ 3 3 3 ]
Material "diffuse" "rgb reflectance" [ 1 1 1 ]
AttributeBegin
ActiveTransform EndTime
)" + motion + R"(
ActiveTransform All
Shape "trianglemesh" "point3 P" [ -2 -1 10  0 -1 10  0 1 10  -2 1 10 ] "integer indices" [ 0 2 1 0 3 2 ]
AttributeEnd
)";
}

// Mean radiance of the left and right halves of the image.
std::pair<double, double> halves(const RenderResult& r) {
  const ImageRgb img = film_mean(r.film);
  double left = 0, right = 0;
  for (int y = 0; y < img.height; ++y)
    for (int x = 0; x < img.width; ++x) (x < img.width / 2 ? left : right) += img.rgb[3 * (y * img.width + x)];
  const double n = img.width * img.height / 2.0;
  return {left / n, right / n};
}

constexpr double kLit = 3.0 / M_PI;
// The quad covers the full height of the middle half of the image's rows.
constexpr double kRows = 0.5;

TEST(MotionBlur, AStaticQuadCoversOneHalf) {
  const auto [left, right] = halves(testing::render_text(quad_scene("")));
  EXPECT_NEAR(left, kLit * kRows, 0.02 * kLit);
  EXPECT_NEAR(right, 0.0, 1e-6);
}

TEST(MotionBlur, AQuadMovingByItsWidthSpreadsOverBothHalves) {
  // Coverage ramps from 0 to 1 across the left half and back down across the
  // right: each half gets half of the quad's light.
  RenderResult r = testing::render_text(quad_scene("Translate 2 0 0"));
  const auto [left, right] = halves(r);
  EXPECT_NEAR(left, 0.5 * kLit * kRows, 0.02 * kLit);
  EXPECT_NEAR(right, 0.5 * kLit * kRows, 0.02 * kLit);
  EXPECT_NE(r.stats.effects & kEffectMotionBlur, 0u);
}

TEST(MotionBlur, ACameraMovingTheOtherWaySeesTheSameBlur) {
  // The camera ends at x = -2: the quad, still, sweeps across the view as if
  // it had moved by +2.
  RenderResult r = testing::render_text(quad_scene("", "", "Translate 2 0 0"));
  const auto [left, right] = halves(r);
  EXPECT_NEAR(left, 0.5 * kLit * kRows, 0.02 * kLit);
  EXPECT_NEAR(right, 0.5 * kLit * kRows, 0.02 * kLit);
  EXPECT_NE(r.stats.effects & kEffectMotionBlur, 0u);
}

TEST(MotionBlur, TheShutterSelectsPartOfTheMotion) {
  // Shutter open for the first half of the transform interval: the quad
  // reaches x in [-1, 1]; the right half is covered 1 - x over x in [0, 1],
  // a quarter on average. pbrt-v4 also scales the image by the exposure time 0.5.
  const auto [left, right] = halves(testing::render_text(quad_scene("Translate 2 0 0", R"("float shutterclose" 0.5)")));
  EXPECT_NEAR(right, 0.5 * 0.25 * kLit * kRows, 0.01 * kLit);
  EXPECT_NEAR(left, 0.5 * 0.75 * kLit * kRows, 0.01 * kLit);
}

TEST(MotionBlur, SameSeedGivesTheSameImageForAnyThreadCount) {
  RenderOptions one, three;
  one.threads = 1;
  three.threads = 3;
  SceneDesc d = load_pbrt_string(quad_scene("Translate 2 0 0"), "<motion>", ".");
  d.spp = 8;
  EXPECT_TRUE(testing::films_identical(testing::render_desc(d, one).film, testing::render_desc(d, three).film));
}

}  // namespace
}  // namespace tessera
