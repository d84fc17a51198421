// Outputs never destroy data (render/output_file.h): device nodes, FIFOs and
// links are written through, two outputs or an output and an input on one
// file are refused before rendering, and a replaced file keeps the usual
// permissions.
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <sys/sysmacros.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <future>
#include <string>

#include "../cli_run.h"
#include "../json_read.h"
#include "../test_dir.h"
#include "render/output_file.h"

namespace tessera {
namespace {

namespace fs = std::filesystem;

using testing::read_text;
using testing::run;
using testing::RunResult;

class OutputSafetyTest : public ::testing::Test {
 protected:
  void SetUp() override { dir_ = testing::fresh_test_dir("tessera_outputs"); }
  void TearDown() override { fs::remove_all(dir_); }
  std::string path(const std::string& name) const { return (dir_ / name).string(); }
  void write(const std::string& name, const std::string& text) const { std::ofstream(dir_ / name) << text; }
  // A quick render of the built-in scene with `args`.
  RunResult render(const std::string& args) const { return run("render -q --spp 1 --res 8x8 " + args); }
  fs::path dir_;
};

void expect_one_line_error(const RunResult& r, const std::string& text) {
  EXPECT_NE(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find(text), std::string::npos) << "expected '" << text << "' in: " << r.output;
  size_t lines = 0;
  for (char c : r.output) lines += c == '\n';
  EXPECT_EQ(lines, 1u) << r.output;
}

bool is_fifo(const std::string& p) {
  struct stat st {};
  return lstat(p.c_str(), &st) == 0 && S_ISFIFO(st.st_mode);
}

// Reads a FIFO to its end on another thread (a writer's open blocks until
// a reader has it open).
std::future<std::string> read_fifo(const std::string& p) {
  return std::async(std::launch::async, [p] {
    std::ifstream f(p, std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(f), {});
  });
}

TEST_F(OutputSafetyTest, StatsIntoAFifoIsWrittenThroughAndTheFifoStays) {
  ASSERT_EQ(mkfifo(path("stats.fifo").c_str(), 0644), 0);
  auto text = read_fifo(path("stats.fifo"));
  RunResult r = render("-o " + path("a.exr") + " --stats " + path("stats.fifo"));
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(text.get().find("\"samples_per_second\""), std::string::npos);
  EXPECT_TRUE(is_fifo(path("stats.fifo")));
}

// A character device is written through (as root, replacing /dev/stdout or
// /dev/null with a regular file breaks the system). The test makes its own
// node like /dev/null where it may (mknod needs root); /dev/null itself
// takes only write_output here, which writes through before any rename.
TEST_F(OutputSafetyTest, CharacterDevicesAreWrittenThroughNeverReplaced) {
  const std::string node = path("null");
  const bool own_node = mknod(node.c_str(), S_IFCHR | 0666, makedev(1, 3)) == 0;
  const std::string target = own_node ? node : "/dev/null";
  RunResult r = render("-o " + path("a.exr") + " --preview " + target + " --stats " + target + " --guide-out " + target +
                       " --guide qtable");
  EXPECT_EQ(r.exit_code, 0) << r.output;
  struct stat st {};
  ASSERT_EQ(lstat(target.c_str(), &st), 0);
  EXPECT_TRUE(S_ISCHR(st.st_mode)) << target << " was replaced";
  write_output(target, [](const std::string& p) { std::ofstream(p) << "x"; });
  ASSERT_EQ(lstat(target.c_str(), &st), 0);
  EXPECT_TRUE(S_ISCHR(st.st_mode));
}

TEST_F(OutputSafetyTest, ALinkIsFollowedNotReplaced) {
  fs::create_directories(dir_ / "real");
  fs::create_symlink(dir_ / "real" / "stats.json", dir_ / "link.json");  // dangling until written
  fs::create_symlink("real/image.exr", dir_ / "link.exr");                // relative
  RunResult r = render("-o " + path("link.exr") + " --no-preview --stats " + path("link.json"));
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_TRUE(fs::is_symlink(dir_ / "link.json"));
  EXPECT_TRUE(fs::is_symlink(dir_ / "link.exr"));
  EXPECT_NE(read_text(dir_ / "real" / "stats.json").find("\"spp\""), std::string::npos);
  EXPECT_GT(fs::file_size(dir_ / "real" / "image.exr"), 0u);
}

TEST_F(OutputSafetyTest, TwoOutputsOnOneFileAreRefusedBeforeRendering) {
  write("out.exr", "old");
  expect_one_line_error(render("-o " + path("out.exr") + " --stats " + path("out.exr")),
                        "-o '" + path("out.exr") + "' and --stats '" + path("out.exr") + "' are the same file");
  // Spelled differently, or a hard link: the same file all the same.
  fs::create_directories(dir_ / "sub");
  expect_one_line_error(render("-o " + path("a.exr") + " --stats " + path("s.json") + " --guide qtable --guide-out " +
                               path("sub/../s.json")),
                        "are the same file");
  fs::create_hard_link(dir_ / "out.exr", dir_ / "alias.json");
  expect_one_line_error(render("-o " + path("out.exr") + " --stats " + path("alias.json")), "are the same file");
  EXPECT_EQ(read_text(dir_ / "out.exr"), "old");
}

TEST_F(OutputSafetyTest, AnOutputOnAnInputIsRefused) {
  ASSERT_EQ(render("-o " + path("tex.exr") + " --no-preview").exit_code, 0);
  write("scene.pbrt", R"(LookAt 0 0 -5 0 0 0 0 1 0
Camera "perspective" "float fov" [ 40 ]
Film "rgb" "integer xresolution" [ 8 ] "integer yresolution" [ 8 ]
WorldBegin
LightSource "point" "rgb I" [ 1 1 1 ] "point3 from" [ 0 0 -2 ]
Include "geometry.pbrt"
)");
  write("geometry.pbrt", R"(Texture "t" "spectrum" "imagemap" "string filename" "tex.exr"
Material "diffuse" "texture reflectance" "t"
Shape "trianglemesh" "point3 P" [ -1 -1 0 1 -1 0 0 1 0 ] "integer indices" [ 0 1 2 ]
)");
  const std::string scene = path("scene.pbrt") + " ";
  const uintmax_t tex_size = fs::file_size(dir_ / "tex.exr");
  expect_one_line_error(render(scene + "-o " + path("tex.exr")), "would overwrite an input of this render (a file the scene reads '");
  expect_one_line_error(render(scene + "-o " + path("b.exr") + " --stats " + path("scene.pbrt")), "(the scene file '");
  expect_one_line_error(render(scene + "-o " + path("b.exr") + " --stats " + path("geometry.pbrt")), "geometry.pbrt')");
  EXPECT_EQ(fs::file_size(dir_ / "tex.exr"), tex_size);
  EXPECT_NE(read_text(dir_ / "scene.pbrt").find("WorldBegin"), std::string::npos);
}

TEST_F(OutputSafetyTest, TheCheckpointBeingResumedIsNotOverwrittenByAnotherOutput) {
  const std::string ckpt = path("c.ckpt");
  ASSERT_EQ(render("-o " + path("a.exr") + " --checkpoint " + ckpt).exit_code, 0);
  const std::string before = read_text(ckpt);
  expect_one_line_error(run("render -q --spp 2 --res 8x8 -o " + path("a.exr") + " --resume " + ckpt + " --stats " + ckpt),
                        "would overwrite an input of this render (--resume '");
  EXPECT_EQ(read_text(ckpt), before);
  // Continuing the checkpoint it resumes is what --checkpoint is for.
  RunResult r = run("render -q --spp 2 --res 8x8 -o " + path("a.exr") + " --resume " + ckpt + " --checkpoint " + ckpt);
  EXPECT_EQ(r.exit_code, 0) << r.output;
}

TEST_F(OutputSafetyTest, StatsGoToStdoutWithDash) {
  RunResult r = run("render -q --spp 1 --res 8x8 -o " + path("a.exr") + " --no-preview --stats -");
  EXPECT_EQ(r.exit_code, 0) << r.output;
  // stdout holds the JSON and the line naming the image; nothing names "-".
  EXPECT_NE(r.output.find("\"samples_per_second\""), std::string::npos) << r.output;
  EXPECT_EQ(r.output.find("wrote -"), std::string::npos) << r.output;
  expect_one_line_error(render("-o " + path("a.exr") + " --preview -"), "--preview '-': this output cannot go to stdout");
}

TEST_F(OutputSafetyTest, AWrittenFileHasTheUsualPermissionsAndNoTemporaryStays) {
  ASSERT_EQ(render("-o " + path("a.exr") + " --stats " + path("s.json")).exit_code, 0);
  const mode_t mask = umask(022);
  umask(mask);
  EXPECT_EQ(fs::status(dir_ / "a.exr").permissions(), static_cast<fs::perms>(0666 & ~mask));
  // A file that existed keeps its mode.
  fs::permissions(dir_ / "s.json", static_cast<fs::perms>(0640));
  ASSERT_EQ(render("-o " + path("a.exr") + " --stats " + path("s.json")).exit_code, 0);
  EXPECT_EQ(fs::status(dir_ / "s.json").permissions(), static_cast<fs::perms>(0640));
  for (const auto& e : fs::directory_iterator(dir_)) EXPECT_NE(e.path().filename().string()[0], '.') << e.path();
}

TEST(OutputFile, AFailedWriteLeavesTheOldFileAndNoTemporary) {
  const fs::path dir = testing::fresh_test_dir("tessera_output_file");
  const std::string p = (dir / "x.json").string();
  std::ofstream(p) << "old";
  EXPECT_THROW(write_output(p, [](const std::string& tmp) {
                 std::ofstream(tmp) << "half";
                 throw std::runtime_error("disk full");
               }),
               std::runtime_error);
  EXPECT_EQ(read_text(p), "old");
  size_t files = 0;
  for (const auto& e : fs::directory_iterator(dir)) files += e.is_regular_file();
  EXPECT_EQ(files, 1u);
  fs::remove_all(dir);
}

TEST(OutputFile, LinkLoopsAndOddNodesAreOneLineErrors) {
  const fs::path dir = testing::fresh_test_dir("tessera_output_file");
  fs::create_symlink(dir / "b", dir / "a");
  fs::create_symlink(dir / "a", dir / "b");
  EXPECT_THROW(check_output_path((dir / "a").string(), "--stats"), std::runtime_error);
  fs::create_directories(dir / "folder");
  try {
    check_output_path((dir / "folder").string(), "--stats");
    ADD_FAILURE() << "a folder was accepted";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("is a folder"), std::string::npos) << e.what();
  }
  fs::remove_all(dir);
}

}  // namespace
}  // namespace tessera
