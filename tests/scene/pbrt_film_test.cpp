// Film: exposure (ISO, shutter), white balance, sensors, maxcomponentvalue.
#include "scene/named_spectra.h"
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

TEST(PbrtFilm, WhiteBalanceStartsFromPbrtsIlluminants) {
  // pbrt-v4's "6500" is a daylight of 6503.6 K, within a hair of D65: nearly no change.
  const Mat3 d65 = white_balance_srgb(6500.f);
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) EXPECT_NEAR(d65[i][j], i == j ? 1.f : 0.f, 0.01f) << i << j;
  // Below 4000 K it starts from a blackbody: the Planckian locus (CIE 1931,
  // tabulated) at 2000 K and 3000 K.
  EXPECT_NEAR(blackbody_xy(2000.f).x, 0.5267f, 0.003f);
  EXPECT_NEAR(blackbody_xy(2000.f).y, 0.4133f, 0.003f);
  EXPECT_NEAR(blackbody_xy(3000.f).x, 0.4369f, 0.003f);
  EXPECT_NEAR(blackbody_xy(3000.f).y, 0.4041f, 0.003f);
  // The balance maps that white to D65's chromaticity.
  const Vec2 w = blackbody_xy(3000.f * 1.4388f / 1.4380f);
  const Vec3 balanced = white_balance_xyz(3000.f) * Vec3(w.x / w.y, 1.f, (1.f - w.x - w.y) / w.y);
  const Float sum = balanced.x + balanced.y + balanced.z;
  EXPECT_NEAR(balanced.x / sum, 0.3127f, 1e-4f);
  EXPECT_NEAR(balanced.y / sum, 0.3290f, 1e-4f);
  // Warm light balanced for 3000 K loses its orange cast: blue is boosted.
  const Mat3 m = white_balance_srgb(3000.f);
  EXPECT_GT((m * Rgb(1.f)).z, 1.5f * (m * Rgb(1.f)).x);
  // Through the film: whitebalance with ISO 200.
  SceneDesc s = load_with("Film \"rgb\" \"float whitebalance\" 3000 \"float iso\" 200\n");
  const Rgb r = s.film.pixel_from_radiance * Rgb(1.f), expected = 2.f * (m * Rgb(1.f));
  EXPECT_NEAR(r.x, expected.x, 1e-5f);
  EXPECT_NEAR(r.z, expected.z, 1e-5f);
  // The two halves compose to the whole (the clamp sits between them).
  const Rgb halves = s.film.pixel_from_sensor * (s.film.sensor_from_radiance * Rgb(0.2f, 0.5f, 0.9f));
  const Rgb whole = s.film.pixel_from_radiance * Rgb(0.2f, 0.5f, 0.9f);
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(halves[c], whole[c], 1e-5f);
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
