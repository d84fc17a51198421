// SIGTERM or Ctrl-C while a scene loads stops the load (scene/load_stop.h):
// the command ends with status 130 and a line saying nothing was written,
// instead of loading to the end of a scene that may never end.
#include <gtest/gtest.h>

#include <sys/stat.h>

#include <filesystem>
#include <string>

#include "../cli_run.h"
#include "../test_dir.h"

namespace tessera {
namespace {

namespace fs = std::filesystem;

// The scene is a FIFO fed without end (a scene file still being written, or
// simply too large to wait for): only the signal can end the load. The
// timeout only catches a load that ignores the signal; it is not a speed target.
TEST(LoadInterruptCli, SigtermStopsALoadThatWouldNotEnd) {
  const fs::path dir = testing::fresh_test_dir("load_interrupt");
  const std::string fifo = (dir / "endless.pbrt").string();
  ASSERT_EQ(mkfifo(fifo.c_str(), 0600), 0);
  const std::string out = (dir / "out.exr").string();
  const std::string feed = "(printf 'Camera \"perspective\"\\nWorldBegin\\nShape \"sphere\"\\n'; yes 'Translate 0 0 0') > " +
                           fifo + " 2>/dev/null &";
  const std::string render = "timeout -s KILL 60 " + std::string(TESSERA_BINARY) + " render " + fifo + " -o " + out +
                             " 2>&1 & pid=$!; sleep 1; kill -TERM $pid; wait $pid";
  const testing::RunResult r = testing::run_shell(feed + " " + render);
  EXPECT_EQ(r.exit_code, 130) << r.output;
  EXPECT_NE(r.output.find("interrupted while loading the scene; nothing was rendered or written"), std::string::npos)
      << r.output;
  EXPECT_FALSE(fs::exists(out));
  fs::remove_all(dir);
}

}  // namespace
}  // namespace tessera
