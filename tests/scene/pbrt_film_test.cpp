// Film: exposure (ISO, shutter), white balance, sensors, maxcomponentvalue.
#include "scene/pbrt_film.h"
#include "scene_test_helpers.h"

namespace tessera {
namespace {

using test::kTriangle;
using test::load_error;

SceneDesc load_with(const std::string& options) {
  return load_pbrt_string(options + "WorldBegin\n" + kTriangle, "test.pbrt", ".");
}

TEST(PbrtFilm, DefaultsRecordRadianceUnchanged) {
  SceneDesc s = load_with("");
  EXPECT_EQ(s.film.pixel_from_radiance, Mat3(1.f));
  EXPECT_FALSE(std::isfinite(s.film.max_component_value));
}

TEST(PbrtFilm, IsoAndShutterScaleTheImage) {
  EXPECT_EQ(load_with("Film \"rgb\" \"float iso\" 150\n").film.pixel_from_radiance, Mat3(1.5f));
  EXPECT_EQ(load_with("Camera \"perspective\" \"float shutteropen\" 0.5 \"float shutterclose\" 2.5\n")
                .film.pixel_from_radiance,
            Mat3(2.f));
  // Film before or after the camera: the same.
  EXPECT_EQ(load_with("Film \"rgb\" \"float iso\" 50\nCamera \"perspective\" \"float shutterclose\" 4\n")
                .film.pixel_from_radiance,
            Mat3(2.f));
  EXPECT_NE(load_error("Camera \"perspective\" \"float shutteropen\" 1 \"float shutterclose\" 1\nWorldBegin\n")
                .find("bad.pbrt:1: the shutter never opens"),
            std::string::npos);
  EXPECT_NE(load_error("Film \"rgb\" \"float iso\" 0\nWorldBegin\n").find("bad.pbrt:1: film \"iso\" must be positive"),
            std::string::npos);
  EXPECT_NE(load_error("Film \"rgb\" \"float maxcomponentvalue\" -1\nWorldBegin\n").find("maxcomponentvalue"),
            std::string::npos);
}

Rgb srgb_of_daylight_white(Float kelvin) {
  // The white of daylight at `kelvin` in linear sRGB (Y = 1), from the same
  // chromaticities pbrt-v4's white balance starts from.
  const double t = kelvin, x = t <= 7000. ? -4.6070e9 / (t * t * t) + 2.9678e6 / (t * t) + 0.09911e3 / t + 0.244063
                                           : -2.0064e9 / (t * t * t) + 1.9018e6 / (t * t) + 0.24748e3 / t + 0.237040;
  const double y = -3.0 * x * x + 2.870 * x - 0.275;
  const Vec3 xyz(static_cast<Float>(x / y), 1.f, static_cast<Float>((1 - x - y) / y));
  return Rgb(3.2404542f * xyz.x - 1.5371385f * xyz.y - 0.4985314f * xyz.z,
             -0.9692660f * xyz.x + 1.8760108f * xyz.y + 0.0415560f * xyz.z,
             0.0556434f * xyz.x - 0.2040259f * xyz.y + 1.0572252f * xyz.z);
}

TEST(PbrtFilm, WhiteBalanceMakesThatIlluminantsWhiteNeutral) {
  for (Float kelvin : {3000.f, 5000.f, 6500.f, 9000.f}) {
    SCOPED_TRACE(kelvin);
    const Rgb balanced = white_balance_srgb(kelvin) * srgb_of_daylight_white(kelvin);
    EXPECT_NEAR(balanced.x / balanced.y, 1.f, 2e-3f);
    EXPECT_NEAR(balanced.z / balanced.y, 1.f, 2e-3f);
  }
  // Warm light balanced for 3000 K loses its orange cast: blue is boosted.
  const Mat3 m = white_balance_srgb(3000.f);
  EXPECT_GT((m * Rgb(1.f)).z, 1.5f * (m * Rgb(1.f)).x);
  // Through the film: whitebalance with ISO 200.
  SceneDesc s = load_with("Film \"rgb\" \"float whitebalance\" 3000 \"float iso\" 200\n");
  const Rgb r = s.film.pixel_from_radiance * Rgb(1.f), expected = 2.f * (m * Rgb(1.f));
  EXPECT_NEAR(r.x, expected.x, 1e-5f);
  EXPECT_NEAR(r.z, expected.z, 1e-5f);
}

TEST(PbrtFilm, CameraSensorsWarnAndBalanceForD65ByDefault) {
  SceneDesc s = load_with("Film \"rgb\" \"string sensor\" \"canon_eos_100d\" \"float iso\" 150\n");
  const Mat3 expected = 1.5f * white_balance_srgb(6500.f);
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) EXPECT_NEAR(s.film.pixel_from_radiance[i][j], expected[i][j], 1e-6f);
  bool warned = false;
  for (const std::string& w : s.warnings) warned |= w.find("test.pbrt:1: sensor \"canon_eos_100d\"") != std::string::npos;
  EXPECT_TRUE(warned);
}

}  // namespace
}  // namespace tessera
