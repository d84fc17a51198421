// What the film records of the radiance it sees: exposure (ISO, shutter) and
// maxcomponentvalue, through a whole render.
#include <gtest/gtest.h>

#include <algorithm>

#include "render_helpers.h"
#include "scene/pbrt_film.h"

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

TEST(FilmSensor, MaxComponentValueBoundsEverySampleInSensorSpace) {
  // pbrt-v4 clamps the sensor's values, XYZ for its default CIE 1931 sensor:
  // no pixel's XYZ (a mean of clamped samples) exceeds the cap.
  auto xyz = [](const ImageRgb& img, size_t p) {
    const float r = img.rgb[3 * p], g = img.rgb[3 * p + 1], b = img.rgb[3 * p + 2];
    return Vec3(0.412453f * r + 0.357580f * g + 0.180423f * b, 0.212671f * r + 0.715160f * g + 0.072169f * b,
                0.019334f * r + 0.119193f * g + 0.950227f * b);
  };
  const ImageRgb base = film_mean(testing::render_text(lit_plane("")).film);
  float brightest = 0.f;
  for (size_t p = 0; p < base.rgb.size() / 3; ++p) brightest = std::max(brightest, max_component(xyz(base, p)));
  const float cap = 0.5f * brightest;
  const ImageRgb capped =
      film_mean(testing::render_text(lit_plane("\"float maxcomponentvalue\" [ " + std::to_string(cap) + " ]")).film);
  float capped_max = 0.f;
  for (size_t p = 0; p < base.rgb.size() / 3; ++p) {
    capped_max = std::max(capped_max, max_component(xyz(capped, p)));
    for (int c = 0; c < 3; ++c) EXPECT_LE(capped.rgb[3 * p + c], base.rgb[3 * p + c] + 1e-6f);
  }
  EXPECT_LE(capped_max, cap * (1.f + 1e-4f));
  EXPECT_GT(capped_max, 0.9f * cap);
  // Scaled, not clipped per channel: a pixel keeps its hue (red:green 2:1).
  const size_t centre = 3 * (8 * 16 + 8);
  EXPECT_NEAR(capped.rgb[centre] / capped.rgb[centre + 1], base.rgb[centre] / base.rgb[centre + 1], 0.05f);
}

// A sharp vertical edge (emission 1 on one side, 0 on the other) seen through
// each pixel filter: a column at distance d from the edge records the share
// of the filter on the bright side, integral f over (-r, d) / integral f.
// Mitchell and sinc overshoot beyond 1 and below 0 there: their negative
// lobes carry negative sample weights.
double edge_column(const ImageRgb& img, int x) {
  double s = 0;
  for (int y = 0; y < img.height; ++y) s += img.rgb[3 * (y * img.width + x)];
  return s / img.height;
}

TEST(FilmSensor, EveryPixelFilterGivesItsEdgeProfile) {
  for (const char* type : {"box", "gaussian", "triangle", "mitchell", "sinc"}) {
    SCOPED_TRACE(type);
    const std::string scene = std::string(R"(
LookAt 0 0 0  0 0 1  0 1 0
Camera "perspective" "float fov" [ 20 ]
Film "rgb" "integer xresolution" [ 32 ] "integer yresolution" [ 8 ]
Sampler "independent" "integer pixelsamples" [ 2048 ]
Integrator "path" "integer maxdepth" [ 1 ]
PixelFilter ")") + type + R"("
WorldBegin
AreaLightSource "diffuse" "rgb L" [ 1 1 1 ] "bool twosided" true
Shape "trianglemesh" "point3 P" [ -100 -100 10  0 -100 10  0 100 10  -100 100 10 ] "integer indices" [ 0 1 2 0 2 3 ]
)";
    SceneDesc desc = load_pbrt_string(scene, "<edge>", ".");
    const FilterDesc filter = desc.filter;
    const ImageRgb img = film_mean(testing::render_desc(std::move(desc), RenderOptions{}).film);
    // Which side is lit depends on the camera's handedness; the test does not care.
    const bool left_lit = edge_column(img, 0) > 0.5;
    auto bright_share = [&](double d) {  // integral of f over the lit side of a pixel centre d from the edge
      double lit = 0, all = 0;
      const int n = 20000;
      for (int i = 0; i < n; ++i) {
        const double x = (i + 0.5) / n * 2 * filter.radius - filter.radius;
        const double f = pixel_filter_1d(filter, static_cast<Float>(x), filter.radius);
        all += f;
        if ((left_lit && x + d < 0) || (!left_lit && x + d > 0)) lit += f;
      }
      return lit / all;
    };
    const bool negative_lobes = std::string(type) == "mitchell" || std::string(type) == "sinc";
    double worst = 0, lowest_expected = 1, got_at_lowest = 0;
    for (int x = 0; x < 32; ++x) {
      const double d = x + 0.5 - 16.0, got = edge_column(img, x), expected = bright_share(d);
      worst = std::max(worst, std::abs(got - expected));
      if (expected < lowest_expected) lowest_expected = expected, got_at_lowest = got;
      if (!negative_lobes) {
        EXPECT_GE(got, 0.0);
        EXPECT_LE(got, 1.0 + 1e-6);
      }
    }
    // 16384 samples per column; signed weights (sinc's most) add noise.
    EXPECT_LT(worst, negative_lobes ? 0.04 : 0.015);
    if (negative_lobes) {
      // The undershoot on the dark side of the edge is there, in sign and size.
      ASSERT_LT(lowest_expected, -0.005);
      EXPECT_LT(got_at_lowest, 0.5 * lowest_expected);
    }
  }
}

}  // namespace
}  // namespace tessera
