// Scenes that asked Embree for rays it refuses (its assertion aborted the
// process, and with it every rank of a farm): each renders, finite, or is
// one line naming file:line with a non-zero exit, on every CPU backend.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>

#include "../cli_run.h"
#include "../exr_read.h"
#include "../json_read.h"
#include "../test_dir.h"

namespace tessera {
namespace {

namespace fs = std::filesystem;
using testing::exr_channels;
using testing::json_number;
using testing::read_text;
using testing::run;
using testing::RunResult;

// A diffuse plane at z = 0 facing the camera at z = -5.
const char* kPlane =
    "Material \"diffuse\" \"rgb reflectance\" [ 0.5 0.5 0.5 ]\n"
    "Shape \"trianglemesh\" \"point3 P\" [ -10 -10 0  10 -10 0  10 10 0  -10 10 0 ] \"integer indices\" [ 0 1 2 0 2 3 ]\n";

std::string scene(const std::string& camera, const std::string& world) {
  return "LookAt 0 0 -5  0 0 0  0 1 0\n" + camera +
         "\nFilm \"rgb\" \"integer xresolution\" [ 8 ] \"integer yresolution\" [ 8 ]\nWorldBegin\n" + world + kPlane;
}

class HostileRaysTest : public ::testing::Test {
 protected:
  void SetUp() override { dir_ = testing::fresh_test_dir("tessera_hostile_rays"); }
  void TearDown() override { fs::remove_all(dir_); }
  std::string write(const std::string& name, const std::string& text) {
    std::ofstream(dir_ / name) << text;
    return (dir_ / name).string();
  }
  std::string path(const std::string& name) const { return (dir_ / name).string(); }
  // Renders `file` with `args`; the image must be written and finite.
  std::string render_ok(const std::string& file, const std::string& args) {
    const std::string out = path("ok.exr"), stats = path("ok.json");
    fs::remove(out);
    const RunResult r = run("render -q --no-preview --spp 4 --seed 1 " + args + " " + file + " -o " + out + " --stats " + stats);
    EXPECT_EQ(r.exit_code, 0) << args << ": " << r.output;
    if (r.exit_code != 0) return "";
    for (float v : exr_channels(out)) EXPECT_TRUE(std::isfinite(v)) << args;
    return read_text(stats);
  }
  // The render is refused: one line naming `where`, exit status 2 (a scene error), nothing written.
  void expect_refused(const std::string& file, const std::string& args, const std::string& where) {
    const std::string out = path("refused.exr");
    const RunResult r = run("render -q --no-preview --spp 4 " + args + " " + file + " -o " + out);
    EXPECT_EQ(r.exit_code, 2) << args << ": " << r.output;
    EXPECT_NE(r.output.find(where), std::string::npos) << "expected '" << where << "' in: " << r.output;
    size_t lines = 0;
    for (char c : r.output) lines += c == '\n';
    EXPECT_EQ(lines, 1u) << r.output;
    EXPECT_FALSE(fs::exists(out));
  }
  fs::path dir_;
};

const char* kLight = "LightSource \"point\" \"rgb I\" [ 10 10 10 ] \"point3 from\" [ 0 0 -2 ]\n";

TEST_F(HostileRaysTest, LensOrScreenWindowBeyondTheLimitsIsRefused) {
  const std::string lens = write("lens.pbrt", scene("Camera \"perspective\" \"float lensradius\" [ 2e18 ]", kLight));
  expect_refused(lens, "", "lens.pbrt:2: the camera's rays start at (");
  const std::string window = write(
      "window.pbrt", scene("Camera \"orthographic\" \"float screenwindow\" [ -2e18 2e18 -2e18 2e18 ]", kLight));
  expect_refused(window, "", "window.pbrt:2: the camera's rays start at (");
  // The camera transform's scale stretches the orthographic window just as far.
  const std::string scaled = write("scaled.pbrt", "Scale 1e-19 1e-19 1\n" + scene("Camera \"orthographic\"", kLight));
  expect_refused(scaled, "", "scaled.pbrt:3: the camera's rays start at (");
  // Directions whose squares overflow normalise to nothing (pbrt-v4's too).
  const std::string wide = write(
      "wide.pbrt", scene("Camera \"perspective\" \"float screenwindow\" [ -1e30 1e30 -1e30 1e30 ]", kLight));
  expect_refused(wide, "", "wide.pbrt:2: the camera's ray directions overflow");
  const std::string focus = write(
      "focus.pbrt", scene("Camera \"perspective\" \"float lensradius\" [ 0.1 ] \"float focaldistance\" [ 1e30 ]", kLight));
  expect_refused(focus, "--backend bvh", "focus.pbrt:2: the camera's ray directions overflow");
  // What is within the limits renders.
  render_ok(write("near.pbrt", scene("Camera \"perspective\" \"float lensradius\" [ 1e17 ]", kLight)), "");
}

// Light paths start at the light: Embree refused the ray from beyond
// 1.8e18. pbrt-v4's I / d^2 overflows to black past 1.8e19 (the issue's
// light at 2e19 with I = 1e38 rendered black, exit 0, here too).
TEST_F(HostileRaysTest, LightsBeyondTheLimitsAreRefused) {
  const std::string point = write(
      "point.pbrt", scene("Camera \"perspective\"", "LightSource \"point\" \"rgb I\" [ 1e38 1e38 1e38 ] \"point3 from\" [ 0 0 -2e19 ]\n"));
  expect_refused(point, "", "point.pbrt:5: the light is at (0, 0, -2e+19): beyond +-1e+18");
  expect_refused(point, "--light-paths on", "point.pbrt:5: the light is at");
  const std::string spot = write("spot.pbrt", "Integrator \"bdpt\"\n" + scene("Camera \"perspective\"",
                                 "AttributeBegin\nTranslate 0 0 -5e18\nLightSource \"spot\" \"rgb I\" [ 1e30 1e30 1e30 ]\n"
                                 "AttributeEnd\n"));
  expect_refused(spot, "--backend bvh", "spot.pbrt:8: the light is at (0, 0, -5e+18)");
  // A direction or an intensity that overflows single precision.
  const std::string aim = write("aim.pbrt", scene("Camera \"perspective\"",
                                "LightSource \"spot\" \"point3 from\" [ 0 0 0 ] \"point3 to\" [ 3e38 3e38 0 ]\n"));
  expect_refused(aim, "", "aim.pbrt:5: the light's direction from \"from\" to \"to\" overflows");
  const std::string bright = write("bright.pbrt", scene("Camera \"perspective\"",
                                   "LightSource \"point\" \"rgb I\" [ 1e38 1 1 ] \"float scale\" [ 1e10 ]\n"));
  expect_refused(bright, "", "bright.pbrt:5: the light's emission");
}

// A point light far out but within the limits is as bright as I / d^2 says:
// the plane's radiance is reflectance / pi * I / d^2 (light, camera and
// plane on one axis).
TEST_F(HostileRaysTest, FarPointLightWithinTheLimitsHasItsAnalyticBrightness) {
  const std::string far = write(
      "far.pbrt", scene("Camera \"perspective\" \"float fov\" [ 10 ]",
                        "LightSource \"point\" \"rgb I\" [ 2.5e35 2.5e35 2.5e35 ] \"point3 from\" [ 0 0 -5e17 ]\n"));
  for (const char* args : {"--backend embree", "--backend bvh", "--light-paths on"}) {
    render_ok(far, args);
    const std::vector<float> px = exr_channels(path("ok.exr"));
    double sum = 0.0;
    for (size_t i = 0; i < 3 * 64; ++i) sum += px[i];  // R, G, B (the variance layer follows)
    EXPECT_NEAR(sum / (3 * 64), 0.5 / M_PI, 0.002) << args;
  }
}

// A camera in an unbounded medium of very thin density scatters its missing
// rays about 1e18 out, where the next ray cannot be traced: the tracer
// takes it as a miss (the path leaves the scene) and counts it.
TEST_F(HostileRaysTest, ThinMediumRendersAndCountsTheRaysItRefused) {
  const std::string thin = write(
      "thin.pbrt",
      "MakeNamedMedium \"thin\" \"string type\" \"homogeneous\" \"rgb sigma_a\" [ 0 0 0 ] "
      "\"rgb sigma_s\" [ 1e-18 1e-18 1e-18 ]\nMediumInterface \"\" \"thin\"\n" +
          scene("Camera \"perspective\" \"float fov\" [ 90 ]",
                std::string("MediumInterface \"thin\"\nLightSource \"infinite\" \"rgb L\" [ 1 1 1 ]\n") + kLight));
  for (const char* args : {"--backend embree", "--backend bvh", "--backend emulated-device", "--light-paths on"}) {
    const std::string stats = render_ok(thin, args);
    EXPECT_GT(json_number(stats, "untraceable_rays"), 0.0) << args << ": " << stats;
  }
  // A scene whose rays all stay within reach has none.
  const std::string stats = render_ok(write("plain.pbrt", scene("Camera \"perspective\"", kLight)), "");
  EXPECT_EQ(json_number(stats, "untraceable_rays"), 0.0) << stats;
}

}  // namespace
}  // namespace tessera
