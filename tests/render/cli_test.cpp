// The binary end to end: bad input gets one clear line naming file:line and a
// non-zero exit; good input writes EXR + PNG; compare reports sizes.
#include <OpenEXR/ImfChannelList.h>
#include <OpenEXR/ImfDoubleAttribute.h>
#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfInputFile.h>
#include <OpenEXR/ImfStringAttribute.h>
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

#include "../test_dir.h"
#include "../cli_run.h"
#include "../exr_read.h"
#include "../json_read.h"
#include "render_helpers.h"
#include "render/device_api.h"

namespace tessera {
namespace {

namespace fs = std::filesystem;

using testing::run;
using testing::RunResult;
using testing::json_number;

class CliTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = testing::fresh_test_dir("tessera_cli");
  }
  void TearDown() override { fs::remove_all(dir_); }
  std::string write(const std::string& name, const std::string& text) {
    std::ofstream(dir_ / name) << text;
    return (dir_ / name).string();
  }
  // Renders the built-in scene with `args` (which must succeed) and returns
  // its stats JSON, written to `name` in the test's folder.
  std::string render_stats(const std::string& args, const std::string& name) {
    const std::string stats = (dir_ / name).string(), out = (dir_ / "render.exr").string();
    RunResult r = run("render -q " + args + " -o " + out + " --stats " + stats);
    EXPECT_EQ(r.exit_code, 0) << r.output;
    return testing::read_text(stats);
  }
  // The same for door-ajar guided by the Q-table at 32x24 (seed 3): where
  // guided roulette, learned NEE and the guide ratio all have work to do.
  std::string door_guided_stats(const std::string& args, const std::string& name, int spp = 64) {
    return render_stats(testing::source_dir() + "/scenes/door-ajar.pbrt --res 32x24 --spp " + std::to_string(spp) +
                            " --seed 3 --guide qtable " + args,
                        name);
  }
  fs::path dir_;
};

const char* kHeader = R"(LookAt 0 0 -5 0 0 0 0 1 0
Camera "perspective" "float fov" [ 40 ]
Film "rgb" "integer xresolution" [ 8 ] "integer yresolution" [ 8 ]
WorldBegin
LightSource "point" "rgb I" [ 1 1 1 ] "point3 from" [ 0 0 -2 ]
)";

void expect_one_line_error(const RunResult& r, const std::string& where) {
  EXPECT_NE(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find(where), std::string::npos) << "expected '" << where << "' in: " << r.output;
  EXPECT_NE(r.output.find("error"), std::string::npos) << r.output;
  size_t lines = 0;
  for (char c : r.output) lines += c == '\n';
  EXPECT_EQ(lines, 1u) << r.output;
}

// Outputs that cannot be written are found before rendering (the render
// asked for here would take hours), with one line naming the option and path.
TEST_F(CliTest, UnwritableOutputsFailBeforeRendering) {
  const std::string missing = (dir_ / "no-such-folder").string();
  const std::string good = (dir_ / "ok.exr").string();
  const std::string slow = "render -q --spp 1000000 --res 512x512 ";
  expect_one_line_error(run(slow + "-o " + missing + "/x.exr"), "-o '" + missing + "/x.exr': folder '" + missing + "' does not exist");
  expect_one_line_error(run(slow + "-o " + good + " --preview " + missing + "/x.png"), "--preview '");
  expect_one_line_error(run(slow + "-o " + good + " --stats " + missing + "/s.json"), "--stats '");
  expect_one_line_error(run(slow + "-o " + good + " --checkpoint " + missing + "/c.ckpt"), "--checkpoint '");
  expect_one_line_error(run(slow + "-o " + good + " --guide-out " + missing + "/g.guide"), "--guide-out '");
  fs::create_directories(dir_ / "folder.exr");
  expect_one_line_error(run(slow + "-o " + (dir_ / "folder.exr").string()), "is a folder");
  // A folder that permission bits call writable, to root too, where no file can be made.
  if (fs::is_directory("/proc/self"))
    expect_one_line_error(run(slow + "-o " + good + " --stats /proc/self/s.json"), "--stats '/proc/self/s.json': folder");
  EXPECT_FALSE(fs::exists(good));
  for (const auto& entry : fs::directory_iterator(dir_))  // the write checks leave nothing behind
    EXPECT_EQ(entry.path().filename().string().rfind(".tessera-write-check", 0), std::string::npos) << entry.path();
}

// A film that cannot fit in memory is refused before rendering, naming the
// resolution and what it needs (it used to render, then die of
// std::bad_alloc writing the images). The address-space limit stands in for
// a small machine.
TEST_F(CliTest, FilmTooLargeForMemoryFailsBeforeRendering) {
  const std::string out = (dir_ / "big.exr").string();
  const RunResult r = testing::run_shell("ulimit -v 3000000; " + std::string(TESSERA_BINARY) +
                                         " render -q --spp 1000000 --res 16384x8192 -o " + out);
  expect_one_line_error(r, "16384x8192 needs about");
  EXPECT_NE(r.output.find("of memory this process may use"), std::string::npos) << r.output;
  EXPECT_FALSE(fs::exists(out));
  // The same limit leaves room for an ordinary image.
  const RunResult ok = testing::run_shell("ulimit -v 3000000; MALLOC_ARENA_MAX=2 " + std::string(TESSERA_BINARY) +
                                          " render -q --threads 2 --spp 1 --res 64x64 -o " + out);
  EXPECT_EQ(ok.exit_code, 0) << ok.output;
}

TEST_F(CliTest, BadNumber) {
  auto f = write("bad_number.pbrt", std::string(kHeader) + "Shape \"sphere\" \"float radius\" [ 1.2.3 ]\n");
  expect_one_line_error(run("render -q " + f + " -o " + (dir_ / "x.exr").string()), "bad_number.pbrt:6");
}

TEST_F(CliTest, NanCoordinate) {
  auto f = write("nan.pbrt", std::string(kHeader) +
                                 "Shape \"trianglemesh\" \"point3 P\" [ 0 0 0 1 0 0 nan 1 0 ] \"integer indices\" [ 0 1 2 ]\n");
  expect_one_line_error(run("render -q " + f), "nan.pbrt:6");
}

TEST_F(CliTest, IndexOutOfRange) {
  auto f = write("index.pbrt", std::string(kHeader) +
                                   "Shape \"trianglemesh\" \"point3 P\" [ 0 0 0 1 0 0 0 1 0 ] \"integer indices\" [ 0 1 7 ]\n");
  expect_one_line_error(run("render -q " + f), "index.pbrt:6");
}

TEST_F(CliTest, MissingInclude) {
  auto f = write("include.pbrt", std::string(kHeader) + "Include \"nowhere.pbrt\"\n");
  expect_one_line_error(run("render -q " + f), "include.pbrt:6");
}

TEST_F(CliTest, MissingPly) {
  auto f = write("ply.pbrt", std::string(kHeader) + "Shape \"plymesh\" \"string filename\" \"missing.ply\"\n");
  expect_one_line_error(run("render -q " + f), "ply.pbrt:6");
}

TEST_F(CliTest, EmptyScene) {
  auto f = write("empty.pbrt", "Camera \"perspective\"\nWorldBegin\n");
  RunResult r = run("render -q " + f);
  expect_one_line_error(r, "empty.pbrt");
}

TEST_F(CliTest, MissingSceneFile) {
  RunResult r = run("render -q " + (dir_ / "does-not-exist.pbrt").string());
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.output.find("does-not-exist.pbrt"), std::string::npos) << r.output;
}

TEST_F(CliTest, UnknownDirectiveWarnsAndRenders) {
  auto f = write("warn.pbrt", std::string(kHeader) + "FancyDirective 1 2 3\nShape \"sphere\"\n");
  std::string out = (dir_ / "warn.exr").string();
  RunResult r = run("render -q --spp 2 " + f + " -o " + out);
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("warn.pbrt:6"), std::string::npos) << r.output;
  EXPECT_TRUE(fs::exists(out));
  EXPECT_TRUE(fs::exists(dir_ / "warn.png"));
}

TEST_F(CliTest, RenderStatsAndCompare) {
  std::string a = (dir_ / "a.exr").string(), b = (dir_ / "b.exr").string(), c = (dir_ / "c.exr").string();
  std::string stats = (dir_ / "stats.json").string();
  ASSERT_EQ(run("render -q --res 24x16 --spp 4 --seed 3 -o " + a + " --stats " + stats).exit_code, 0);
  ASSERT_EQ(run("render -q --res 24x16 --spp 4 --seed 3 --threads 1 -o " + b).exit_code, 0);
  const std::string json = testing::read_text(stats);
  for (const char* key : {"\"spp\": 4", "\"samples_per_second\"", "\"rays_per_second\"", "\"mean_path_length\"",
                          "\"zero_contribution_fraction\"", "\"nonfinite_samples_rejected\": 0", "\"effects\"",
                          "\"transport\": \"spectral\""})
    EXPECT_NE(json.find(key), std::string::npos) << key << " in " << json;
  // The built-in box's light is orange: --spectral auto chose spectral; off is RGB.
  const std::string rgb = render_stats("--res 8x8 --spp 2 --spectral off", "rgb.json");
  EXPECT_NE(rgb.find("\"transport\": \"rgb\""), std::string::npos) << rgb;
  // Same seed, different thread count: identical images, zero error.
  RunResult same = run("compare --json " + a + " " + b);
  EXPECT_EQ(same.exit_code, 0);
  EXPECT_EQ(json_number(same.output, "relmse"), 0.0) << same.output;
  ASSERT_EQ(run("render -q --res 16x16 --spp 1 -o " + c).exit_code, 0);
  RunResult mismatch = run("compare " + a + " " + c);
  EXPECT_NE(mismatch.exit_code, 0);
  EXPECT_NE(mismatch.output.find("sizes differ"), std::string::npos) << mismatch.output;
}

TEST_F(CliTest, ExrHasVarianceLayerAndMetadata) {
  std::string out = (dir_ / "m.exr").string();
  ASSERT_EQ(run("render -q --res 16x12 --spp 3 --seed 9 -o " + out).exit_code, 0);
  Imf::InputFile file(out.c_str());
  const Imf::Header& h = file.header();
  for (const char* ch : {"R", "G", "B", "variance.R", "variance.G", "variance.B"})
    EXPECT_NE(h.channels().findChannel(ch), nullptr) << ch;
  auto* spp = h.findTypedAttribute<Imf::DoubleAttribute>("spp");
  ASSERT_NE(spp, nullptr);
  EXPECT_EQ(spp->value(), 3.0);
  auto* seed = h.findTypedAttribute<Imf::StringAttribute>("seed");
  ASSERT_NE(seed, nullptr);
  EXPECT_EQ(seed->value(), "9");
  auto* effects = h.findTypedAttribute<Imf::StringAttribute>("effects");
  ASSERT_NE(effects, nullptr);
  EXPECT_EQ(effects->value(), "diffuse, area-lights");
  auto* transport = h.findTypedAttribute<Imf::StringAttribute>("transport");
  ASSERT_NE(transport, nullptr);
  EXPECT_EQ(transport->value(), "spectral");  // the built-in Cornell box's light is orange
  auto* light_sampler = h.findTypedAttribute<Imf::StringAttribute>("light_sampler");
  ASSERT_NE(light_sampler, nullptr);
  EXPECT_EQ(light_sampler->value(), "bvh");  // pbrt-v4's default
  EXPECT_NE(h.findTypedAttribute<Imf::DoubleAttribute>("seconds"), nullptr);
  EXPECT_NE(h.findTypedAttribute<Imf::StringAttribute>("software"), nullptr);
}

TEST_F(CliTest, TimeBudgetStopsTheRender) {
  std::string stats = (dir_ / "t.json").string();
  RunResult r = run("render -q --res 32x32 --time 0.5 -o " + (dir_ / "t.exr").string() + " --stats " + stats);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const std::string json = testing::read_text(stats);
  EXPECT_NE(json.find("\"stop_reason\": \"time\""), std::string::npos) << json;
  EXPECT_EQ(json.find("\"spp\": 0,"), std::string::npos) << json;
}

TEST_F(CliTest, BadOptionValues) {
  EXPECT_NE(run("render --res 12by4").exit_code, 0);
  EXPECT_NE(run("render -o out.png").exit_code, 0);
  EXPECT_NE(run("render --spp -3").exit_code, 0);
}

// Saving and loading a guide cache from the command line, and the one-line
// errors for a cache that cannot be used.
TEST_F(CliTest, GuideCacheOptions) {
  const std::string cache = (dir_ / "cornell.guide").string(), out = (dir_ / "o.exr").string();
  RunResult saved = run("render -q --res 16x16 --spp 4 --guide qtable --guide-out " + cache + " -o " + out);
  ASSERT_EQ(saved.exit_code, 0) << saved.output;
  ASSERT_TRUE(fs::exists(cache));
  RunResult loaded = run("render -q --res 16x16 --spp 2 --guide-in " + cache + " -o " + out);
  EXPECT_EQ(loaded.exit_code, 0) << loaded.output;
  EXPECT_NE(loaded.output.find("loaded from"), std::string::npos) << loaded.output;

  RunResult contradict = run("render -q --spp 1 --guide none --guide-in " + cache + " -o " + out);
  EXPECT_NE(contradict.exit_code, 0);
  EXPECT_NE(contradict.output.find("contradict"), std::string::npos) << contradict.output;
  const std::string other_scene = write("other.pbrt", std::string(kHeader) + "Shape \"sphere\"\n");
  RunResult other = run("render " + other_scene + " -q --spp 1 --guide-in " + cache + " -o " + out);
  EXPECT_NE(other.exit_code, 0);
  EXPECT_NE(other.output.find("another scene"), std::string::npos) << other.output;
  RunResult junk = run("render -q --spp 1 --guide-in " + write("junk.guide", "not a cache") + " -o " + out);
  EXPECT_NE(junk.exit_code, 0);
  EXPECT_NE(junk.output.find("not a Tessera guide cache"), std::string::npos) << junk.output;
  EXPECT_NE(run("render --guide bogus").exit_code, 0);
}

// A network keeps the settings it was trained with: a --neural-* option that
// differs from the network loaded from a file or a checkpoint is refused in
// one line, not ignored, and one given where no network guides is refused too.
// Slow-ish (13 runs of the binary, each loading its ~260 libraries; a
// ctest test of its own): one per refusal it checks.
TEST_F(CliTest, NeuralOptionsThatContradictTheGuideAreRefused) {
  const std::string net = (dir_ / "cornell.nguide").string(), out = (dir_ / "n.exr").string();
  RunResult saved =
      run("render -q --res 16x16 --spp 2 --guide neural --neural-width 4 --neural-steps 3 --guide-out " + net + " -o " + out);
  ASSERT_EQ(saved.exit_code, 0) << saved.output;
  EXPECT_EQ(run("render -q --res 16x16 --spp 1 --guide-in " + net + " -o " + out).exit_code, 0);
  RunResult same = run("render -q --res 16x16 --spp 1 --guide neural --neural-width 4 --neural-steps 3 --guide-in " +
                       net + " -o " + out);
  EXPECT_EQ(same.exit_code, 0) << same.output;
  RunResult wider = run("render -q --res 16x16 --spp 1 --neural-width 8 --guide-in " + net + " -o " + out);
  EXPECT_NE(wider.exit_code, 0);
  EXPECT_NE(wider.output.find("trained with --neural-width 4, not 8"), std::string::npos) << wider.output;
  RunResult steps = run("render -q --res 16x16 --spp 1 --guide neural --neural-steps 48 --guide-in " + net + " -o " + out);
  EXPECT_NE(steps.exit_code, 0);
  EXPECT_NE(steps.output.find("--neural-steps 3, not 48"), std::string::npos) << steps.output;
  RunResult rate = run("render -q --res 16x16 --spp 1 --neural-lr 0.01 --guide-in " + net + " -o " + out);
  EXPECT_NE(rate.exit_code, 0);
  EXPECT_NE(rate.output.find("--neural-lr 0.02, not 0.01"), std::string::npos) << rate.output;
  RunResult table = run("render -q --res 16x16 --spp 1 --guide qtable --neural-width 4 -o " + out);
  EXPECT_NE(table.exit_code, 0);
  EXPECT_NE(table.output.find("--neural-width is for --guide neural"), std::string::npos) << table.output;
  RunResult none = run("render -q --res 16x16 --spp 1 --guide none --neural-table 12 -o " + out);
  EXPECT_NE(none.exit_code, 0);
  EXPECT_NE(none.output.find("--neural-table is for --guide neural"), std::string::npos) << none.output;

  // guide-viz learns a network where --neural-* options ask for one, and holds a loaded one to them.
  const std::string dist = (dir_ / "q.exr").string(), at = " --point 0 0.2 0 --normal 0 1 0 --distribution " + dist;
  RunResult viz = run("guide-viz --train-spp 2 --neural-width 4" + at);
  EXPECT_EQ(viz.exit_code, 0) << viz.output;
  EXPECT_NE(viz.output.find("trained the neural guide"), std::string::npos) << viz.output;
  EXPECT_TRUE(fs::exists(dist));
  RunResult viz_wider = run("guide-viz --neural-width 8 --guide-in " + net + at);
  EXPECT_NE(viz_wider.exit_code, 0);
  EXPECT_NE(viz_wider.output.find("trained with --neural-width 4, not 8"), std::string::npos) << viz_wider.output;

  // A checkpoint's network is held to the options given with --resume as well.
  const std::string ckpt = (dir_ / "n.ckpt").string();
  const std::string trained = " --res 16x16 --guide neural --neural-width 4 --neural-steps 3 -o " + out;
  ASSERT_EQ(run("render -q --spp 2 --checkpoint " + ckpt + trained).exit_code, 0);
  RunResult resumed = run("render -q --spp 3 --resume " + ckpt + trained);
  EXPECT_EQ(resumed.exit_code, 0) << resumed.output;
  RunResult resumed_wider =
      run("render -q --spp 3 --res 16x16 --guide neural --neural-width 8 -o " + out + " --resume " + ckpt);
  EXPECT_NE(resumed_wider.exit_code, 0);
  EXPECT_NE(resumed_wider.output.find("--resume " + ckpt + ": its network was trained with --neural-width 4, not 8"),
            std::string::npos)
      << resumed_wider.output;
}

// The learning schedule reaches the render and its stats; fewer learning
// samples mean fewer guide updates; bad values are refused.
// Ctrl-C (SIGINT) during a long render: it stops after the pass under way
// and writes the image so far, its stats and the checkpoint, and exits 130.
TEST_F(CliTest, InterruptWritesTheImageSoFar) {
  const std::string out = (dir_ / "interrupted.exr").string(), stats = (dir_ / "interrupted.json").string();
  const std::string ckpt = (dir_ / "interrupted.ckpt").string();
  RunResult r = testing::run_shell(std::string(TESSERA_BINARY) + " render -q --time 120 --res 64x48 --threads 1 -o " +
                                   out + " --stats " + stats + " --checkpoint " + ckpt +
                                   " & pid=$!; sleep 3; kill -INT $pid; wait $pid; echo exit=$?");
  EXPECT_NE(r.output.find("exit=130"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("interrupted"), std::string::npos) << r.output;
  ASSERT_TRUE(fs::exists(out)) << r.output;
  EXPECT_TRUE(fs::exists(ckpt));
  const std::string json = testing::read_text(stats);
  EXPECT_NE(json.find("\"stop_reason\": \"interrupted\""), std::string::npos) << json;
  EXPECT_GT(json_number(json, "spp"), 0.0) << json;
  // The checkpoint resumes it.
  RunResult resumed = run("render -q --spp " + std::to_string(static_cast<int>(json_number(json, "spp")) + 8) +
                          " --res 64x48 -o " + out + " --resume " + ckpt);
  EXPECT_EQ(resumed.exit_code, 0) << resumed.output;
}

TEST_F(CliTest, GuideLearningScheduleOptions) {
  auto updates = [&](const std::string& args, const std::string& name) {
    return render_stats("--res 16x16 --spp 12 --seed 2 --guide qtable " + args, name);
  };
  const std::string some = updates("--guide-learn-spp 2 --guide-learn-every 3", "some.json");
  EXPECT_NE(some.find("\"guide_learn_spp\": 2,"), std::string::npos) << some;
  EXPECT_NE(some.find("\"guide_learn_every\": 3,"), std::string::npos) << some;
  const std::string all = updates("--guide-learn-spp 100", "all.json");
  const double some_updates = json_number(some, "guide_updates");
  EXPECT_GT(some_updates, 0.0) << some;
  EXPECT_LT(some_updates, json_number(all, "guide_updates")) << all;
  EXPECT_NE(run("render --guide-learn-every -1").exit_code, 0);
  EXPECT_NE(run("render --guide-learn-spp x").exit_code, 0);
  // The taper is on by default and says so; off reaches the render too.
  EXPECT_NE(some.find("\"guide_learn_taper\": \"on\""), std::string::npos) << some;
  // Every sample learns up to 16 spp either way; of samples 16-39, all without
  // the taper, 10 with it (16, 18, ..., 30 and 32, 36).
  const std::string base = "--res 16x16 --spp 40 --seed 2 --guide qtable --guide-learn-spp 0 --guide-learn-every 1";
  const std::string flat = render_stats(base + " --guide-learn-taper off", "flat.json");
  EXPECT_NE(flat.find("\"guide_learn_taper\": \"off\""), std::string::npos) << flat;
  const std::string tapered = render_stats(base, "tapered.json");
  EXPECT_LT(json_number(tapered, "guide_updates"), json_number(flat, "guide_updates")) << tapered;
  const RunResult bad = run("render --guide-learn-taper maybe");
  EXPECT_NE(bad.exit_code, 0);
  EXPECT_NE(bad.output.find("--guide-learn-taper"), std::string::npos) << bad.output;
}

// --guide-roulette reaches the render: the stats say which rule ran, and only
// the guided one lets the guide take roulette decisions; bad values are refused.
TEST_F(CliTest, GuideRouletteOption) {
  auto stats_of = [&](const std::string& args, const std::string& name) {
    return render_stats("--res 24x24 --spp 16 --seed 3 --guide qtable " + args, name);
  };
  const std::string guided = stats_of("", "guided.json"), thr = stats_of("--guide-roulette throughput", "thr.json");
  EXPECT_NE(guided.find("\"guide_roulette\": \"guided\""), std::string::npos) << guided;
  EXPECT_NE(thr.find("\"guide_roulette\": \"throughput\""), std::string::npos) << thr;
  EXPECT_GT(json_number(guided, "guided_roulette_fraction"), 0.0) << guided;
  EXPECT_EQ(json_number(thr, "guided_roulette_fraction"), 0.0) << thr;
  RunResult bad = run("render --guide-roulette sometimes");
  EXPECT_NE(bad.exit_code, 0);
  EXPECT_NE(bad.output.find("--guide-roulette"), std::string::npos) << bad.output;
}

// --guide-roulette-window reaches the render: a smaller window lets fewer of
// the paths the guide expects light from survive, so paths are shorter (on
// door-ajar, where guided roulette keeps light-carrying paths alive); the
// stats record it; bad values are refused.
TEST_F(CliTest, GuideRouletteWindowOption) {
  auto stats_of = [&](const std::string& args, const std::string& name) { return door_guided_stats(args, name); };
  const std::string wide = stats_of("", "wide.json"), narrow = stats_of("--guide-roulette-window 0.25", "narrow.json");
  EXPECT_EQ(json_number(wide, "guide_roulette_window"), 2.0) << wide;
  EXPECT_EQ(json_number(narrow, "guide_roulette_window"), 0.25) << narrow;
  EXPECT_LT(json_number(narrow, "mean_path_length"), 0.9 * json_number(wide, "mean_path_length")) << narrow;
  RunResult bad = run("render --guide-roulette-window 0");
  EXPECT_NE(bad.exit_code, 0);
  EXPECT_NE(bad.output.find("--guide-roulette-window"), std::string::npos) << bad.output;
}

// --guide-nee learned (default) skips shadow rays where the guide learned
// they bring little (door-ajar's room behind a door gap); always never does.
TEST_F(CliTest, GuideNextEventOption) {
  auto stats_of = [&](const std::string& args, const std::string& name) { return door_guided_stats(args, name); };
  const std::string learned = stats_of("", "learned.json"), always = stats_of("--guide-nee always", "always.json");
  EXPECT_NE(learned.find("\"guide_nee\": \"learned\""), std::string::npos) << learned;
  EXPECT_NE(always.find("\"guide_nee\": \"always\""), std::string::npos) << always;
  EXPECT_GT(json_number(learned, "nee_skipped_fraction"), 0.1) << learned;
  EXPECT_EQ(json_number(always, "nee_skipped_fraction"), 0.0) << always;
  // The mixture weight is learned per cell unless --guide-mix fixes it.
  EXPECT_GT(json_number(learned, "guide_mix_learned_cells"), 0.0) << learned;
  const std::string fixed = stats_of("--guide-mix 0.35", "fixed.json");
  EXPECT_EQ(json_number(fixed, "guide_mix_learned_cells"), 0.0) << fixed;
  EXPECT_NEAR(json_number(fixed, "guide_mean_mix"), 0.35, 1e-6) << fixed;
  RunResult bad = run("render --guide-nee never");
  EXPECT_NE(bad.exit_code, 0);
  EXPECT_NE(bad.output.find("--guide-nee"), std::string::npos) << bad.output;
}

// --guide-max-ratio R: paths whose guided weight passed R sample their BSDF
// alone; with R = 1 a path is guided only while the guide has not raised
// its weight at all, so far more vertices are left to the BSDF. NaN is refused.
TEST_F(CliTest, GuideMaxRatioOption) {
  auto stats_of = [&](const std::string& args, const std::string& name) { return door_guided_stats(args, name, 32); };
  const std::string standard = stats_of("", "standard.json"), tight = stats_of("--guide-max-ratio 1", "tight.json");
  EXPECT_EQ(json_number(standard, "guide_max_ratio"), 8.0) << standard;
  EXPECT_EQ(json_number(tight, "guide_max_ratio"), 1.0) << tight;
  EXPECT_GT(json_number(tight, "guide_withheld_fraction"), json_number(standard, "guide_withheld_fraction") + 0.1)
      << standard << tight;
  for (const char* value : {"0.5", "nan"}) {
    RunResult bad = run(std::string("render --guide-max-ratio ") + value);
    EXPECT_NE(bad.exit_code, 0) << value;
    EXPECT_NE(bad.output.find("--guide-max-ratio"), std::string::npos) << bad.output;
  }
}

TEST_F(CliTest, InfoPrintsEffects) {
  RunResult r = run("info");
  EXPECT_EQ(r.exit_code, 0);
  EXPECT_NE(r.output.find("effects:        diffuse, area-lights"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("36 triangles"), std::string::npos) << r.output;
}

// A PLY mesh whose arrays cannot fit is refused from its header, before its
// body is read: 100 million vertices (a sparse file of 1.2 GB that takes no
// disk) under an address-space limit of 800 MB.
TEST_F(CliTest, PlyMeshTooLargeForMemoryFailsBeforeReading) {
  const uint64_t vertices = 100000000;
  {
    std::ofstream f(dir_ / "huge.ply", std::ios::binary);
    f << "ply\nformat binary_little_endian 1.0\nelement vertex " << vertices
      << "\nproperty float x\nproperty float y\nproperty float z\nelement face 1"
         "\nproperty list uchar int vertex_indices\nend_header\n";
    f.seekp(static_cast<std::streamoff>(f.tellp()) + static_cast<std::streamoff>(vertices * 12));
    const char face[13] = {3};
    f.write(face, sizeof face);
  }
  const std::string scene = write("huge.pbrt", "Camera \"perspective\"\nWorldBegin\n"
                                               "LightSource \"point\" \"point3 from\" [0 3 0] \"rgb I\" [10 10 10]\n"
                                               "Shape \"plymesh\" \"string filename\" \"huge.ply\"\n");
  const RunResult r = testing::run_shell("ulimit -v 800000; " + std::string(TESSERA_BINARY) + " info " + scene);
  expect_one_line_error(r, "huge.pbrt:4: cannot read PLY");
  EXPECT_NE(r.output.find("its 100000000 vertices and 1 faces need about 1.1 GB, more than the"), std::string::npos)
      << r.output;
}

// A scene whose triangles cannot fit once their arrays and BVH are built is
// refused before building them, naming the count and what it needs. An
// 8-million-triangle binary PLY (150 MB, loaded in about 300 MB) under an
// address-space limit that leaves less than its 1.1 GB estimate.
TEST_F(CliTest, SceneTooLargeForMemoryFailsBeforeBuilding) {
  const int n = 2000;  // vertices per side: 2 (n - 1)^2 triangles
  {
    std::ofstream f(dir_ / "grid.ply", std::ios::binary);
    f << "ply\nformat binary_little_endian 1.0\nelement vertex " << n * n
      << "\nproperty float x\nproperty float y\nproperty float z\nelement face " << 2 * (n - 1) * (n - 1)
      << "\nproperty list uchar int vertex_indices\nend_header\n";
    std::vector<float> p;
    p.reserve(3 * static_cast<size_t>(n) * n);
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) p.insert(p.end(), {i * 4.f / n - 2.f, 0.f, j * 4.f / n - 2.f});
    f.write(reinterpret_cast<const char*>(p.data()), static_cast<std::streamsize>(p.size() * sizeof(float)));
    std::vector<char> faces;
    faces.reserve(26 * static_cast<size_t>(n - 1) * (n - 1));
    auto face = [&](int a, int b, int c) {
      faces.push_back(3);
      for (int v : {a, b, c}) faces.insert(faces.end(), reinterpret_cast<char*>(&v), reinterpret_cast<char*>(&v) + 4);
    };
    for (int j = 0; j + 1 < n; ++j)
      for (int i = 0; i + 1 < n; ++i) {
        const int v = j * n + i;
        face(v, v + 1, v + n + 1);
        face(v, v + n + 1, v + n);
      }
    f.write(faces.data(), static_cast<std::streamsize>(faces.size()));
  }
  const std::string scene = write("big.pbrt", "Camera \"perspective\"\nWorldBegin\n"
                                              "LightSource \"point\" \"point3 from\" [0 3 0] \"rgb I\" [10 10 10]\n"
                                              "Shape \"plymesh\" \"string filename\" \"grid.ply\"\n");
  const std::string out = (dir_ / "big.exr").string();
  const RunResult r = testing::run_shell("ulimit -v 1400000; " + std::string(TESSERA_BINARY) +
                                         " render -q --threads 1 --spp 1 --res 16x16 " + scene + " -o " + out);
  expect_one_line_error(r, "the scene's 7992002 triangles need about");
  EXPECT_NE(r.output.find("of memory this process may use"), std::string::npos) << r.output;
  EXPECT_FALSE(fs::exists(out));
}

// Every 64-bit seed is its own (CLI11's int64 clamped seeds from 2^63 up,
// so those all gave one image); a seed or a size out of range is named as such.
TEST_F(CliTest, SeedsAndSizesOutOfRangeAreNamed) {
  auto image = [&](const std::string& seed) {
    const std::string out = (dir_ / ("s" + seed + ".exr")).string();
    const RunResult r = run("render -q --spp 2 --res 8x8 --no-preview --seed " + seed + " -o " + out);
    EXPECT_EQ(r.exit_code, 0) << r.output;
    return testing::exr_channels(out);
  };
  const std::vector<float> a = image("9223372036854775808"), b = image("18446744073709551615");
  EXPECT_NE(a, b);
  expect_one_line_error(run("render -q --spp 1 --res 8x8 --seed 18446744073709551616"), "--seed: expected an integer");
  expect_one_line_error(run("render -q --spp 1 --seed -3"), "--seed");
  expect_one_line_error(run("render -q --spp 1 --res 100000x1"), "--res: 100000x1 is larger than supported");
}

// A scene that warns thousands of times (a curve per hair, say) prints each
// distinct warning a few times and then counts it: not megabytes of log.
TEST_F(CliTest, RepeatedWarningsAreCountedNotPrintedEachTime) {
  std::string text = kHeader;
  for (int i = 0; i < 2000; ++i) text += "TransformBegin\nTransformEnd\n";
  text += "Shape \"sphere\"\n";
  const std::string scene = write("many-warnings.pbrt", text);
  const RunResult r = run("render -q --spp 1 --no-preview -o " + (dir_ / "m.exr").string() + " " + scene);
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("2000 times in all: TransformBegin is deprecated"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("4000 warnings in all, 6 of them shown"), std::string::npos) << r.output;
  size_t warning_lines = 0;
  for (size_t at = r.output.find("warning:"); at != std::string::npos; at = r.output.find("warning:", at + 1)) ++warning_lines;
  EXPECT_EQ(warning_lines, 9u) << r.output;  // 3 of each, a count of each, the total
}

// pbrt-v4 reads gzip-compressed scene files and Includes (scene.pbrt.gz):
// the same picture as from the plain files.
TEST_F(CliTest, GzippedScenesAndIncludesRenderAsPlainOnes) {
  write("geometry.pbrt", "Material \"diffuse\"\nShape \"sphere\" \"float radius\" [ 0.8 ]\n");
  write("plain.pbrt", std::string(kHeader) + "Include \"geometry.pbrt\"\n");
  write("packed.pbrt", std::string(kHeader) + "Include \"geometry.pbrt.gz\"\n");
  ASSERT_EQ(testing::run_shell("cd " + dir_.string() + " && gzip -k geometry.pbrt && gzip packed.pbrt").exit_code, 0);
  auto render = [&](const std::string& scene) {
    const std::string out = (dir_ / (scene + ".exr")).string();
    const RunResult r = run("render -q --spp 4 --no-preview --seed 2 -o " + out + " " + (dir_ / scene).string());
    EXPECT_EQ(r.exit_code, 0) << r.output;
    return testing::exr_channels(out);
  };
  const std::vector<float> plain = render("plain.pbrt"), packed = render("packed.pbrt.gz");
  ASSERT_FALSE(plain.empty());
  EXPECT_TRUE(plain == packed);
}

// A damaged PNG texture is our one line, without libpng's own
// "libpng error: ..." line before it.
TEST_F(CliTest, ADamagedPngTextureIsOneLine) {
  const std::string good = (dir_ / "good.exr").string();
  ASSERT_EQ(run("render -q --spp 1 --res 8x8 -o " + good).exit_code, 0);  // writes good.png beside it
  std::ifstream in(dir_ / "good.png", std::ios::binary);
  const std::string png((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  ASSERT_GT(png.size(), 80u);
  std::ofstream(dir_ / "cut.png", std::ios::binary) << png.substr(0, 60);  // the header, then the data cut off
  const std::string scene = write("png.pbrt", std::string(kHeader) +
                                                  "Texture \"t\" \"spectrum\" \"imagemap\" \"string filename\" \"cut.png\"\n"
                                                  "Material \"diffuse\" \"texture reflectance\" \"t\"\nShape \"sphere\"\n");
  const RunResult r = run("render -q --spp 1 -o " + (dir_ / "o.exr").string() + " " + scene);
  expect_one_line_error(r, "png.pbrt:6: cannot read image");
  EXPECT_EQ(r.output.find("libpng"), std::string::npos) << r.output;
}

}  // namespace
TEST_F(CliTest, BackendsRenderOrRefuseInOneLine) {
  // The portable BVH and the emulated device render and say so in the
  // stats; auto says why it chose; CUDA renders where there is a device and
  // is refused in one line where there is none.
  auto stats_backend = [&](const std::string& backend) {
    const std::string out = (dir_ / (backend + ".exr")).string(), stats = (dir_ / (backend + ".json")).string();
    const RunResult r = run("render --backend " + backend + " --spp 4 --res 16x12 --no-preview -o " + out + " --stats " + stats);
    EXPECT_EQ(r.exit_code, 0) << r.output;
    EXPECT_NE(r.output.find("backend: "), std::string::npos) << r.output;
    std::ifstream in(stats);
    const std::string json((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    return json;
  };
  EXPECT_NE(stats_backend("bvh").find("\"backend\": \"bvh\""), std::string::npos);
  EXPECT_NE(stats_backend("emulated-device").find("\"backend\": \"emulated-device\""), std::string::npos);
  std::string why;
  const bool device = cuda_device_count(&why) > 0;
  // auto: CUDA where there is a device, else Embree.
  EXPECT_NE(stats_backend("auto").find(device ? "\"backend\": \"cuda\"" : "\"backend\": \"embree\""), std::string::npos);
  const std::string out = (dir_ / "cuda.exr").string();
  if (device) {
    EXPECT_EQ(run("render -q --backend cuda --spp 4 --res 16x12 --no-preview -o " + out).exit_code, 0);
  } else {
    expect_one_line_error(run("render -q --backend cuda --spp 4 --res 16x12 --no-preview -o " + out), "--backend cuda");
  }
}

}  // namespace tessera
