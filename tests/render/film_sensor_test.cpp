// What the film records of the radiance it sees: exposure (ISO, shutter) and
// maxcomponentvalue, through a whole render.
#include <gtest/gtest.h>

#include <algorithm>

#include "render_helpers.h"

namespace tessera {
namespace {

std::string lit_plane(const std::string& film_params, const std::string& camera_params = "") {
  return R"(
LookAt 0 5 0  0 0 0  0 0 1
Camera "perspective" "float fov" [ 30 ] )" + camera_params + R"(
Film "rgb" "integer xresolution" [ 16 ] "integer yresolution" [ 16 ] )" + film_params + R"(
Sampler "independent" "integer pixelsamples" [ 8 ]
Integrator "path" "integer maxdepth" [ 3 ]
WorldBegin
LightSource "point" "rgb I" [ 40 20 10 ] "point3 from" [ 0 2 0 ]
Material "diffuse" "rgb reflectance" [ 0.5 0.5 0.5 ]
Shape "trianglemesh" "point3 P" [ -10 0 -10  10 0 -10  10 0 10  -10 0 10 ] "integer indices" [ 0 1 2 0 2 3 ]
)";
}

TEST(FilmSensor, IsoAndShutterScaleEveryPixel) {
  const ImageRgb base = film_mean(testing::render_text(lit_plane("")).film);
  const ImageRgb iso = film_mean(testing::render_text(lit_plane("\"float iso\" [ 150 ]")).film);
  const ImageRgb shutter = film_mean(testing::render_text(lit_plane("", "\"float shutterclose\" [ 0.25 ]")).film);
  ASSERT_GT(testing::image_mean(base), 0.01);
  for (size_t i = 0; i < base.rgb.size(); ++i) {
    EXPECT_NEAR(iso.rgb[i], 1.5f * base.rgb[i], 1e-5f * (1.f + base.rgb[i]));
    EXPECT_NEAR(shutter.rgb[i], 0.25f * base.rgb[i], 1e-5f * (1.f + base.rgb[i]));
  }
}

TEST(FilmSensor, MaxComponentValueBoundsEverySample) {
  const ImageRgb base = film_mean(testing::render_text(lit_plane("")).film);
  const float brightest = *std::max_element(base.rgb.begin(), base.rgb.end());
  const float cap = 0.5f * brightest;
  const ImageRgb capped =
      film_mean(testing::render_text(lit_plane("\"float maxcomponentvalue\" [ " + std::to_string(cap) + " ]")).film);
  float capped_max = 0.f;
  for (size_t i = 0; i < base.rgb.size(); ++i) {
    capped_max = std::max(capped_max, capped.rgb[i]);
    EXPECT_LE(capped.rgb[i], base.rgb[i] + 1e-6f);
  }
  EXPECT_LE(capped_max, cap * (1.f + 1e-5f));
  // Scaled, not clipped per channel: a pixel keeps its hue (red:green 2:1).
  const size_t centre = 3 * (8 * 16 + 8);
  EXPECT_NEAR(capped.rgb[centre] / capped.rgb[centre + 1], base.rgb[centre] / base.rgb[centre + 1], 0.05f);
}

}  // namespace
}  // namespace tessera
