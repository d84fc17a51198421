// The error estimate from the command line: --target-error stops a render
// and says so (stats JSON, EXR metadata, the summary line); impossible
// targets end on --time; --snapshot-every writes intermediate EXRs and a
// CSV, the last one the final image bit for bit; `tessera compare` prints
// each image's own estimate. Bad values exit non-zero naming the option.
#include <OpenEXR/ImfChannelList.h>
#include <OpenEXR/ImfDoubleAttribute.h>
#include <OpenEXR/ImfFrameBuffer.h>
#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfInputFile.h>
#include <OpenEXR/ImfStringAttribute.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <regex>
#include <string>
#include <vector>

#include "../test_dir.h"
#include "../cli_run.h"
#include "../exr_read.h"
#include "../json_read.h"
#include "render/image_output.h"
#include "furnace_scene.h"
#include "render_helpers.h"

namespace tessera {
namespace {

namespace fs = std::filesystem;
using testing::run;
using testing::RunResult;
using testing::exr_channels;
using testing::json_number;
using testing::json_numbers;
using testing::read_text;

double exr_number(const std::string& path, const char* name) {
  Imf::InputFile file(path.c_str());
  auto* a = file.header().findTypedAttribute<Imf::DoubleAttribute>(name);
  return a ? a->value() : std::nan("");
}

std::string exr_string(const std::string& path, const char* name) {
  Imf::InputFile file(path.c_str());
  auto* a = file.header().findTypedAttribute<Imf::StringAttribute>(name);
  return a ? a->value() : "<none>";
}

// A rejected option value: non-zero exit, and the first line of the
// message names the option. (CLI11's own validation errors add a second
// line, "Run with --help for more information.")
void expect_option_error(const RunResult& r, const std::string& option) {
  EXPECT_NE(r.exit_code, 0) << r.output;
  const std::string first = r.output.substr(0, r.output.find('\n'));
  EXPECT_NE(first.find(option), std::string::npos) << "expected '" << option << "' in the first line of: " << r.output;
  size_t lines = 0;
  for (char c : r.output) lines += c == '\n';
  EXPECT_LE(lines, 2u) << r.output;
}

class ErrorEstimateCli : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = testing::fresh_test_dir("tessera_errcli");
    furnace_ = (dir_ / "furnace.pbrt").string();
    // 16x16; its Sampler asks for 4 spp: --target-error must replace that, as --time does.
    std::ofstream(furnace_) << testing::furnace_scene(0.5, 5, 16, 4);
  }
  void TearDown() override { fs::remove_all(dir_); }
  std::string path(const std::string& name) const { return (dir_ / name).string(); }

  fs::path dir_;
  std::string furnace_;
};

TEST_F(ErrorEstimateCli, TargetErrorStopsAndIsRecorded) {
  const std::string out = path("t.exr"), stats = path("t.json");
  RunResult r = run("render -q " + furnace_ + " --target-error 0.01 --seed 5 --no-preview -o " + out + " --stats " + stats);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("stopped by target-error"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("runs until then"), std::string::npos) << r.output;  // no --time/--spp limit, said up front
  const std::string json = read_text(stats);
  EXPECT_NE(json.find("\"stop_reason\": \"target-error\""), std::string::npos) << json;
  EXPECT_EQ(json_number(json, "target_error"), 0.01) << json;
  const double est = json_number(json, "estimated_relmse");
  EXPECT_GE(est, 0.0) << json;
  EXPECT_LE(est, 0.01) << json;
  // The scene's 4 spp did not limit it: 0.01 needs more on this furnace.
  EXPECT_GT(json_number(json, "spp"), 4.0) << json;
  // Per pass: the first estimate itself (the top-level figure comes first
  // in the file), then one per pass; the last at or below the target, the
  // one before above it.
  std::vector<double> per_pass = json_numbers(json, "estimated_relmse");
  ASSERT_GE(per_pass.size(), 3u) << json;
  per_pass.erase(per_pass.begin());
  EXPECT_EQ(per_pass.size(), static_cast<size_t>(json_number(json, "passes"))) << json;
  EXPECT_EQ(per_pass.back(), est);
  EXPECT_GT(per_pass[per_pass.size() - 2], 0.01) << json;
  // The EXR says the same.
  EXPECT_EQ(exr_string(out, "stop_reason"), "target-error");
  EXPECT_EQ(exr_number(out, "target_error"), 0.01);
  EXPECT_NEAR(exr_number(out, "estimated_relmse"), est, 1e-8 * est);
}

TEST_F(ErrorEstimateCli, ImpossibleTargetStopsOnTime) {
  const std::string stats = path("t.json");
  RunResult r = run("render -q " + furnace_ + " --target-error 1e-12 --time 0.5 --no-preview -o " + path("t.exr") +
                    " --stats " + stats);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("stopped by time (target relMSE 1e-12 not reached: estimated"), std::string::npos) << r.output;
  const std::string json = read_text(stats);
  EXPECT_NE(json.find("\"stop_reason\": \"time\""), std::string::npos) << json;
  EXPECT_EQ(json_number(json, "target_error"), 1e-12) << json;
  EXPECT_GT(json_number(json, "estimated_relmse"), 1e-12) << json;
}

TEST_F(ErrorEstimateCli, SppLimitComesFirst) {
  const std::string stats = path("t.json");
  RunResult r = run("render -q " + furnace_ + " --target-error 1e-6 --spp 8 --no-preview -o " + path("t.exr") +
                    " --stats " + stats);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("stopped by spp (target relMSE 1e-06 not reached"), std::string::npos) << r.output;
  const std::string json = read_text(stats);
  EXPECT_NE(json.find("\"stop_reason\": \"spp\""), std::string::npos) << json;
  EXPECT_EQ(json_number(json, "spp"), 8.0) << json;
}

TEST_F(ErrorEstimateCli, BadTargetErrorValues) {
  for (const char* bad : {"0", "abc", "-0.1", "nan"}) {
    const std::string out = path("bad.exr");
    RunResult r = run("render -q " + furnace_ + " --target-error " + bad + " -o " + out);
    expect_option_error(r, "--target-error");
    EXPECT_FALSE(fs::exists(out)) << bad;
  }
}

TEST_F(ErrorEstimateCli, SnapshotsAtDoublingSpp) {
  const std::string out = path("conv.exr"), stats = path("conv.json");
  RunResult r = run("render -q --res 32x32 --spp 16 --seed 2 --snapshot-every doubling --no-preview -o " + out +
                    " --stats " + stats);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const fs::path snaps = dir_ / "conv-snapshots";
  const std::vector<uint32_t> expected_spp = {1, 2, 4, 8, 16};
  std::vector<std::string> files;
  for (uint32_t spp : expected_spp) {
    char name[64];
    std::snprintf(name, sizeof name, "conv-%06uspp.exr", spp);
    files.push_back((snaps / name).string());
    ASSERT_TRUE(fs::exists(files.back())) << files.back();
    EXPECT_EQ(exr_number(files.back(), "spp"), spp) << files.back();
  }
  size_t exrs = 0;
  for (const auto& e : fs::directory_iterator(snaps)) exrs += e.path().extension() == ".exr";
  EXPECT_EQ(exrs, expected_spp.size());

  // snapshots.csv: a header and one line per snapshot, in order; the
  // estimate is -1 below 4 spp and then present.
  std::ifstream csv(snaps / "snapshots.csv");
  std::vector<std::string> lines;
  for (std::string l; std::getline(csv, l);) lines.push_back(l);
  ASSERT_EQ(lines.size(), 1 + expected_spp.size());
  EXPECT_EQ(lines[0], "file,spp,seconds,render_seconds,estimated_relmse");
  for (size_t i = 0; i < expected_spp.size(); ++i) {
    const std::string prefix = fs::path(files[i]).filename().string() + "," + std::to_string(expected_spp[i]) + ",";
    EXPECT_EQ(lines[i + 1].rfind(prefix, 0), 0u) << lines[i + 1];
    const double est = std::stod(lines[i + 1].substr(lines[i + 1].rfind(',') + 1));
    if (expected_spp[i] < 4) EXPECT_EQ(est, -1.0) << lines[i + 1];
    else EXPECT_GT(est, 0.0) << lines[i + 1];
  }

  // The stats JSON lists them too.
  const nlohmann::json json = nlohmann::json::parse(read_text(stats));
  ASSERT_TRUE(json.contains("snapshots")) << json;
  std::vector<double> spps;
  for (const auto& snap : json["snapshots"]) spps.push_back(snap["spp"].get<double>());
  EXPECT_EQ(spps, std::vector<double>(expected_spp.begin(), expected_spp.end())) << json;

  // The 16-spp snapshot is taken at the final pass: the final image, bit for
  // bit (mean and variance layers). The 8-spp one is not.
  const std::vector<float> final_px = exr_channels(out);
  EXPECT_EQ(exr_channels(files.back()), final_px);
  EXPECT_NE(exr_channels(files[3]), final_px);
  RunResult same = run("compare --json " + files.back() + " " + out);
  ASSERT_EQ(same.exit_code, 0) << same.output;
  EXPECT_EQ(json_number(same.output, "relmse"), 0.0) << same.output;

  // A fresh render to the same output replaces the earlier snapshots (a
  // stale 16-spp file or CSV line would corrupt a convergence curve).
  ASSERT_EQ(run("render -q --res 32x32 --spp 4 --seed 2 --snapshot-every doubling --no-preview -o " + out).exit_code, 0);
  exrs = 0;
  for (const auto& e : fs::directory_iterator(snaps)) exrs += e.path().extension() == ".exr";
  EXPECT_EQ(exrs, 3u);
  std::ifstream csv2(snaps / "snapshots.csv");
  size_t lines2 = 0;
  for (std::string l; std::getline(csv2, l);) ++lines2;
  EXPECT_EQ(lines2, 1u + 3u);
}

TEST_F(ErrorEstimateCli, BadSnapshotEveryValues) {
  for (const std::string bad : {"0", "2y", "-3", "sometimes"}) {
    const std::string out = path("bad.exr");
    RunResult r = run("render -q --res 8x8 --spp 2 --snapshot-every " + bad + " -o " + out);
    expect_option_error(r, "--snapshot-every");
    std::string quoted = "'";
    quoted += bad;
    quoted += "'";
    EXPECT_NE(r.output.find(quoted), std::string::npos) << r.output;
    EXPECT_FALSE(fs::exists(out)) << bad;
    EXPECT_FALSE(fs::exists(dir_ / "bad-snapshots")) << bad;
  }
}

TEST_F(ErrorEstimateCli, CompareReportsEachImagesOwnEstimate) {
  const std::string a = path("a.exr"), b = path("b.exr"), a_stats = path("a.json");
  ASSERT_EQ(run("render -q --res 24x16 --spp 8 --seed 1 --no-preview -o " + a + " --stats " + a_stats).exit_code, 0);
  ASSERT_EQ(run("render -q --res 24x16 --spp 32 --seed 2 --no-preview -o " + b).exit_code, 0);
  RunResult r = run("compare --json " + a + " " + b);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const double est = json_number(r.output, "estimated_relmse");
  const double ref_est = json_number(r.output, "reference_estimated_relmse");
  EXPECT_GT(est, 0.0) << r.output;
  EXPECT_GT(ref_est, 0.0) << r.output;
  // 4x the samples: much less estimated noise (on this scene far below a
  // quarter at these counts, as dim pixels with one bright sample stop
  // counting as all noise; half is a loose bound).
  EXPECT_LT(ref_est, 0.5 * est) << r.output;
  // The image's estimate is the one its render reported: the EXR holds the
  // mean and variance as 32-bit floats and compare reads them as such.
  const double rendered = json_number(read_text(a_stats), "estimated_relmse");
  EXPECT_NEAR(est, rendered, 1e-5 * rendered) << r.output;

  // Below 4 spp the variance layer is no estimate: -1, as the render reports.
  const std::string one = path("one.exr");
  ASSERT_EQ(run("render -q --res 24x16 --spp 1 --no-preview -o " + one).exit_code, 0);
  RunResult low = run("compare --json " + one + " " + b);
  ASSERT_EQ(low.exit_code, 0) << low.output;
  EXPECT_EQ(json_number(low.output, "estimated_relmse"), -1.0) << low.output;

  // An EXR with no variance layer has no estimate: -1.
  ImageRgb plain{24, 16, std::vector<float>(24 * 16 * 3, 0.5f)};
  const std::string p = path("plain.exr");
  write_exr(p, plain, nullptr, {});
  RunResult none = run("compare --json " + a + " " + p);
  ASSERT_EQ(none.exit_code, 0) << none.output;
  EXPECT_EQ(json_number(none.output, "reference_estimated_relmse"), -1.0) << none.output;
  EXPECT_GT(json_number(none.output, "estimated_relmse"), 0.0) << none.output;

  // Human-readable output mentions both.
  RunResult text = run("compare " + a + " " + b);
  ASSERT_EQ(text.exit_code, 0) << text.output;
  EXPECT_NE(text.output.find("relMSE estimated:"), std::string::npos) << text.output;
  EXPECT_NE(text.output.find("reference noise:"), std::string::npos) << text.output;
}

// Radiance 1e30: the variance of a pixel's mean (~1e59) does not fit a
// float. The EXR stores it saturated (the largest float, never Inf) and says
// how many pixels are; compare then gives no estimate instead of one made
// from the few pixels left (it said 0 before); the render's own estimate,
// computed in double, stands.
TEST_F(ErrorEstimateCli, HugeRadianceSaturatesTheVarianceLayer) {
  const std::string scene = path("bright.pbrt"), out = path("bright.exr"), stats = path("bright.json");
  std::ofstream(scene) << "LookAt 0 0 -4  0 0 0  0 1 0\nCamera \"perspective\" \"float fov\" [ 40 ]\n"
                          "Film \"rgb\" \"integer xresolution\" [ 16 ] \"integer yresolution\" [ 16 ]\n"
                          "Sampler \"independent\" \"integer pixelsamples\" [ 16 ]\nWorldBegin\n"
                          "LightSource \"infinite\" \"rgb L\" [ 1e30 1e30 1e30 ]\n"
                          "Material \"diffuse\" \"rgb reflectance\" [ 0.5 0.5 0.5 ]\nShape \"sphere\" \"float radius\" [ 1 ]\n";
  RunResult r = run("render --guide none --no-preview --snapshot-every doubling -o " + out + " --stats " + stats + " " + scene);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("variance layer exceeds the float range"), std::string::npos) << r.output;
  const std::vector<float> px = exr_channels(out);
  for (float v : px) ASSERT_TRUE(std::isfinite(v));
  const double saturated = exr_number(out, "variance_saturated_pixels");
  EXPECT_GT(saturated, 16.0);
  EXPECT_LT(saturated, 256.0);  // the background's variance is 0
  // Snapshots say so too.
  EXPECT_EQ(exr_number(path("bright-snapshots/bright-000016spp.exr"), "variance_saturated_pixels"), saturated);
  EXPECT_GT(json_number(read_text(stats), "estimated_relmse"), 0.0);
  RunResult c = run("compare --json " + out + " " + out);
  ASSERT_EQ(c.exit_code, 0) << c.output;
  EXPECT_EQ(json_number(c.output, "estimated_relmse"), -1.0) << c.output;
  EXPECT_NE(c.output.find("no error estimate"), std::string::npos) << c.output;
}

TEST_F(ErrorEstimateCli, CompareSizeMismatch) {
  const std::string a = path("a.exr"), c = path("c.exr");
  ASSERT_EQ(run("render -q --res 24x16 --spp 4 --no-preview -o " + a).exit_code, 0);
  ASSERT_EQ(run("render -q --res 16x16 --spp 4 --no-preview -o " + c).exit_code, 0);
  RunResult r = run("compare --json " + a + " " + c);
  EXPECT_NE(r.exit_code, 0) << r.output;
  for (const std::string& s : {std::string("sizes differ"), std::string("24x16"), std::string("16x16"), a, c})
    EXPECT_NE(r.output.find(s), std::string::npos) << "expected '" << s << "' in: " << r.output;
  size_t lines = 0;
  for (char ch : r.output) lines += ch == '\n';
  EXPECT_EQ(lines, 1u) << r.output;
  EXPECT_EQ(r.output.find("\"relmse\""), std::string::npos) << r.output;  // no half-written JSON
}

// EXRs are read at full float precision: a half-float read would turn a
// value above 65504 into Inf (and drop the pixel as NaN/Inf) and round a
// 1e-4 difference on 1.0 away.
TEST_F(ErrorEstimateCli, CompareReadsFloatsNotHalves) {
  ImageRgb a{2, 1, {1e5f, 1e5f, 1e5f, 1.0001f, 1.0001f, 1.0001f}};
  ImageRgb b{2, 1, {1e5f, 1e5f, 1e5f, 1.0f, 1.0f, 1.0f}};
  const std::string pa = path("fa.exr"), pb = path("fb.exr");
  write_exr(pa, a, nullptr, {});
  write_exr(pb, b, nullptr, {});
  RunResult r = run("compare --json " + pa + " " + pb);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_EQ(json_number(r.output, "nonfinite_pixels"), 0.0) << r.output;
  EXPECT_EQ(json_number(r.output, "reference_nonfinite_pixels"), 0.0) << r.output;
  // Pixel 2: d = 1e-4 (to float rounding) on F = 1 in 3 channels of 6 terms.
  const double d = double(1.0001f) - 1.0;
  EXPECT_NEAR(json_number(r.output, "relmse"), 3 * d * d / 1.01 / 6, 1e-3 * (3 * d * d / 1.01 / 6)) << r.output;
}

}  // namespace
}  // namespace tessera
