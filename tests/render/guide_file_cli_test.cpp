// Guide files from the command line: a damaged table guide is one line
// naming the file and what is wrong (render and guide-viz alike), never a
// render biased by it; --guide-out where no guide is learned is refused;
// a valid file renders the same image whichever version holds it.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>
#include <string>

#include "../cli_run.h"
#include "../exr_read.h"
#include "../guide_file_bytes.h"
#include "../test_dir.h"

namespace tessera {
namespace {

namespace fs = std::filesystem;
using testing::run;
using testing::RunResult;

class GuideFileCli : public ::testing::Test {
 protected:
  void SetUp() override { dir_ = testing::fresh_test_dir("tessera_guide_file"); }
  void TearDown() override { fs::remove_all(dir_); }
  std::string path(const std::string& name) const { return (dir_ / name).string(); }
  std::string write(const std::string& name, const std::string& bytes) {
    std::ofstream(dir_ / name, std::ios::binary) << bytes;
    return path(name);
  }
  // A table guide learned on the built-in Cornell box, as its bytes.
  std::string learned_guide() {
    const std::string guide = path("learned.guide");
    RunResult r = run("render -q --res 16x16 --spp 4 --guide qtable --guide-out " + guide + " -o " + path("learn.exr"));
    EXPECT_EQ(r.exit_code, 0) << r.output;
    std::ifstream in(guide, std::ios::binary);
    std::ostringstream s;
    s << in.rdbuf();
    return s.str();
  }
  fs::path dir_;
};

void expect_one_line_error(const RunResult& r, const std::string& expected) {
  EXPECT_NE(r.exit_code, 0) << r.output;
  EXPECT_EQ(r.output.rfind("tessera: error: ", 0), 0u) << r.output;
  EXPECT_NE(r.output.find(expected), std::string::npos) << "expected '" << expected << "' in: " << r.output;
  size_t lines = 0;
  for (char c : r.output) lines += c == '\n';
  EXPECT_EQ(lines, 1u) << r.output;
}

TEST_F(GuideFileCli, DamagedTableGuidesAreOneLineErrorsNamingTheFile) {
  using namespace testing;
  const std::string good = learned_guide();
  const float nan = std::numeric_limits<float>::quiet_NaN(), inf = std::numeric_limits<float>::infinity();
  const uint64_t nodes = guide_payload_get<uint64_t>(good, kGuideNodesAt);
  const int32_t last_cell = guide_payload_get<int32_t>(good, guide_node_at(nodes - 2) + 4);
  std::string flipped = good;
  flipped[flipped.size() / 2] = static_cast<char>(flipped[flipped.size() / 2] ^ 0x10);
  const std::pair<std::string, std::string> cases[] = {
      {guide_payload_set(good, kGuideFloorAt, nan), "corrupt guide cache (the floor is nan, not in [0, 1])"},
      {guide_payload_set(good, guide_value_at(good, 5), inf), "corrupt guide cache (cell 0, entry 5: value inf)"},
      {guide_payload_set(good, kGuideProbAt, -0.25f), "corrupt guide cache (the guide probability is -0.25, not in [0, 1])"},
      {guide_payload_set(good, guide_value_at(good, 5), -1.f), "corrupt guide cache (cell 0, entry 5: value -1)"},
      // The last two nodes are leaves (a split's children come last): one cell for both.
      {guide_payload_set(good, guide_node_at(nodes - 1) + 4, last_cell), "corrupt guide cache (leaf " + std::to_string(nodes - 1) + " and its cell " + std::to_string(last_cell) + ")"},
      {flipped, "corrupt guide cache (checksum mismatch)"},
      {good.substr(0, good.size() - 10), "truncated guide cache ("},
  };
  const std::string out = path("o.exr");
  int i = 0;
  for (const auto& [bytes, problem] : cases) {
    const std::string bad = write("bad" + std::to_string(i++) + ".guide", bytes);
    expect_one_line_error(run("render -q --res 16x16 --spp 1 --guide-in " + bad + " -o " + out), "--guide-in " + bad + ": " + problem);
  }
  EXPECT_FALSE(fs::exists(out));
}

// guide-viz draws nothing from a guide it cannot draw finitely (it used to
// write NaN pixels).
TEST_F(GuideFileCli, GuideVizRefusesAGuideItCannotDrawFinitely) {
  using namespace testing;
  const std::string good = learned_guide();
  const std::string bad = write("nan.guide", guide_payload_set(good, guide_value_at(good, 0), std::numeric_limits<float>::quiet_NaN()));
  const std::string dist = path("q.exr"), greedy = path("greedy.exr");
  RunResult r = run("guide-viz --guide-in " + bad + " --point 0 0.2 0 --normal 0 1 0 --distribution " + dist +
                    " --diagnostic " + greedy);
  expect_one_line_error(r, "--guide-in " + bad + ": corrupt guide cache (cell 0, entry 0: value nan)");
  EXPECT_FALSE(fs::exists(dist));
  EXPECT_FALSE(fs::exists(greedy));
  // The valid file draws, and --guide-out saves it again, byte for byte.
  const std::string copy = path("copy.guide");
  RunResult ok = run("guide-viz --guide-in " + write("good.guide", good) + " --point 0 0.2 0 --normal 0 1 0 --distribution " +
                     dist + " --guide-out " + copy);
  EXPECT_EQ(ok.exit_code, 0) << ok.output;
  EXPECT_TRUE(fs::exists(dist));
  std::ifstream in(copy, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  EXPECT_EQ(s.str(), good);
}

// An output asked for that would not be written is refused before rendering.
TEST_F(GuideFileCli, GuideOutWithoutAGuideIsRefused) {
  const std::string guide = path("g.guide"), out = path("o.exr");
  expect_one_line_error(run("render -q --res 16x16 --spp 1 --guide none --guide-out " + guide + " -o " + out),
                        "--guide-out " + guide + ": no guide is learned to save (--guide none)");
  // auto without anything to guide: a light and nothing it lights.
  const std::string empty = write("empty.pbrt", R"(LookAt 0 0 -5 0 0 0 0 1 0
Camera "perspective" "float fov" [ 40 ]
Film "rgb" "integer xresolution" [ 8 ] "integer yresolution" [ 8 ]
WorldBegin
LightSource "point" "rgb I" [ 1 1 1 ] "point3 from" [ 0 0 -2 ]
)");
  expect_one_line_error(run("render " + empty + " -q --spp 1 --guide-out " + guide + " -o " + out),
                        "--guide-out " + guide + ": no guide is learned to save (auto: ");
  EXPECT_FALSE(fs::exists(guide));
  EXPECT_FALSE(fs::exists(out));
}

// The checks only refuse: a valid file renders as it did, bit for bit, and
// the same fields as version 4 (no checksum) render the same image.
TEST_F(GuideFileCli, ValidGuideRendersTheSameImageFromEitherVersion) {
  const std::string good = learned_guide();
  const std::string v5 = write("v5.guide", good), v4 = write("v4.guide", testing::guide_as_version4(good));
  const std::string a = path("a.exr"), b = path("b.exr"), c = path("c.exr");
  const std::string args = "render -q --res 16x16 --spp 8 --seed 4 --guide-in ";
  ASSERT_EQ(run(args + v5 + " -o " + a).exit_code, 0);
  ASSERT_EQ(run(args + v4 + " -o " + b).exit_code, 0);
  ASSERT_EQ(run(args + v5 + " -o " + c).exit_code, 0);
  EXPECT_EQ(testing::exr_channels(a), testing::exr_channels(b));
  EXPECT_EQ(testing::exr_channels(a), testing::exr_channels(c));
}

}  // namespace
}  // namespace tessera
