// A rank stopped with SIGSTOP, as a hung or suspended process would be, in
// a farm under mpirun (docs/farm.md, "A silent rank"). The rank stops itself
// at a chosen point (TESSERA_TEST_STOP, src/app/farm_test_stop.h), so the
// tests do not race it. Each of them is slow (a lease or a timeout waited
// out, and the kill sequence of Open MPI's abort): a ctest test of its own.
#include <gtest/gtest.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <regex>
#include <string>
#include <thread>

#include "../cli_run.h"
#include "../exr_read.h"
#include "../test_dir.h"
#include "../render/render_helpers.h"

namespace tessera {
namespace {

namespace fs = std::filesystem;
using testing::exr_channels;
using testing::run;
using testing::run_mpi;
using testing::run_shell;
using testing::RunResult;

class FarmStallCli : public ::testing::Test {
 protected:
  void SetUp() override { dir_ = testing::fresh_test_dir("tessera_stall"); }
  void TearDown() override { fs::remove_all(dir_); }
  std::string path(const std::string& name) const { return (dir_ / name).string(); }
  fs::path dir_;
};

const std::string kDoor = testing::source_dir() + "/scenes/door-ajar.pbrt";

// `mpirun -np N tessera ARGS` with rank RANK stopping itself at POINT.
RunResult run_mpi_stopping(int ranks, const std::string& stop, const std::string& args) {
  return run_shell("TESSERA_TEST_STOP=" + stop +
                   " OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 mpirun --oversubscribe -x TESSERA_TEST_STOP -np " +
                   std::to_string(ranks) + " " + TESSERA_BINARY + " " + args);
}

// The pid a rank printed when it stopped itself (0: none).
int stopped_pid(const std::string& output, int rank) {
  std::smatch m;
  const std::regex re("rank " + std::to_string(rank) + " \\(pid ([0-9]+)\\) stops itself");
  return std::regex_search(output, m, re) ? std::stoi(m[1]) : 0;
}

// Whether the process still runs (or is stopped): gone, or dead and not yet
// reaped by init (a zombie), it does not.
bool process_alive(int pid) {
  std::ifstream stat("/proc/" + std::to_string(pid) + "/stat");
  std::string line;
  if (!std::getline(stat, line)) return false;
  const size_t paren = line.rfind(')');
  return paren != std::string::npos && paren + 2 < line.size() && line[paren + 2] != 'Z' && line[paren + 2] != 'X';
}

// mpirun returns once it has sent the kill; the process may take a moment
// to die (a core being written, say).
bool dies_soon(int pid) {
  for (int i = 0; i < 200 && process_alive(pid); ++i) std::this_thread::sleep_for(std::chrono::milliseconds(50));
  return !process_alive(pid);
}

// A worker stopped before it renders its first tile, for the whole render:
// after the lease its tiles go to the other ranks, the farm finishes, every
// output is written, and the master ends the job (mpirun exits 0, the
// stopped process is gone). The image is the local render's, bit for bit,
// unguided and guided (the learning rounds go on without it), on 3 ranks
// and on 2 (the master alone finishes it).
TEST_F(FarmStallCli, StoppedWorkerLeavesTheLocalImage) {
  for (auto [guide, ranks] : {std::pair{"none", 3}, std::pair{"qtable", 3}, std::pair{"qtable", 2}}) {
    const std::string what = std::string("--guide ") + guide + ", " + std::to_string(ranks) + " ranks";
    const std::string args = kDoor + " -q --no-preview --res 64x48 --spp 16 --seed 3 --guide " + guide;
    const std::string local = path(std::string("local-") + guide + ".exr");
    RunResult l = run("render " + args + " -o " + local);
    ASSERT_EQ(l.exit_code, 0) << l.output;
    const std::string exr = path("farm.exr"), stats = path("farm.json");
    fs::remove(exr);
    RunResult farm = run_mpi_stopping(ranks, std::to_string(ranks - 1) + ":tiles",
                                      "render " + args + " --farm-lease 2 -o " + exr + " --stats " + stats);
    EXPECT_EQ(farm.exit_code, 0) << what << "\n" << farm.output;
    const int pid = stopped_pid(farm.output, ranks - 1);
    ASSERT_GT(pid, 0) << what << ": the worker did not stop\n" << farm.output;
    EXPECT_TRUE(dies_soon(pid)) << what << ": the stopped worker outlived the job";
    const std::string rank = "rank " + std::to_string(ranks - 1);
    EXPECT_NE(farm.output.find("tessera: farm: " + rank + " silent for "), std::string::npos) << farm.output;
    EXPECT_NE(farm.output.find("tiles re-issued"), std::string::npos) << farm.output;
    EXPECT_NE(farm.output.find(rank + " silent for"), farm.output.rfind(rank + " silent for")) << farm.output;
    EXPECT_NE(farm.output.find("ending the job without it (every output is written)"), std::string::npos)
        << farm.output;
    ASSERT_TRUE(fs::exists(exr)) << what << "\n" << farm.output;
    EXPECT_TRUE(exr_channels(exr) == exr_channels(local)) << what << ": the image differs from the local one";
    EXPECT_TRUE(fs::exists(stats)) << what;
  }
}

// A worker stopped after it answered the master's stop, before it is
// through MPI_Finalize (which waits for every rank): the master gives it a
// lease, then ends the job with status 0, every output written.
TEST_F(FarmStallCli, WorkerStoppedAtTheVeryEndStillLetsTheJobEnd) {
  const std::string args = kDoor + " -q --no-preview --res 64x48 --spp 8 --seed 3";
  RunResult l = run("render " + args + " -o " + path("local.exr"));
  ASSERT_EQ(l.exit_code, 0) << l.output;
  RunResult farm = run_mpi_stopping(3, "2:bye", "render " + args + " --farm-lease 2 -o " + path("farm.exr"));
  EXPECT_EQ(farm.exit_code, 0) << farm.output;
  const int pid = stopped_pid(farm.output, 2);
  ASSERT_GT(pid, 0) << "the worker did not stop\n" << farm.output;
  EXPECT_TRUE(dies_soon(pid)) << "the stopped worker outlived the job";
  EXPECT_NE(farm.output.find("tessera: farm: a rank did not end within 2 s of the render; ending the job without it"),
            std::string::npos)
      << farm.output;
  ASSERT_TRUE(fs::exists(path("farm.exr"))) << farm.output;
  EXPECT_TRUE(exr_channels(path("farm.exr")) == exr_channels(path("local.exr"))) << "the image differs";
}

// A stopped worker continued (SIGCONT) once its tiles were re-issued: what
// it sends about that pass is ignored, it takes part again from a later
// pass with the master's guide, the image is still the local one, and the
// job ends as any other (no rank left to abort).
TEST_F(FarmStallCli, StoppedWorkerThatWakesUpTakesPartAgain) {
  const std::string args = kDoor + " -q --no-preview --res 64x48 --spp 256 --seed 3 --guide qtable";
  RunResult l = run("render " + args + " -o " + path("local.exr"));
  ASSERT_EQ(l.exit_code, 0) << l.output;
  const std::string log = path("farm.log");
  RunResult farm = run_shell(
      "TESSERA_TEST_STOP=2:tiles OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 mpirun --oversubscribe "
      "-x TESSERA_TEST_STOP -np 3 " + std::string(TESSERA_BINARY) + " render " + args + " --farm-lease 2 -o " +
      path("farm.exr") + " > " + log + " 2>&1 & P=$!; " +
      "for i in $(seq 1 600); do grep -q 'tiles re-issued' " + log + " && break; sleep 0.05; done; " +
      "kill -CONT $(sed -n 's/.*rank 2 (pid \\([0-9]*\\)) stops itself.*/\\1/p' " + log + "); " +
      "wait $P; echo exit=$?; cat " + log);
  EXPECT_NE(farm.output.find("exit=0"), std::string::npos) << farm.output;
  EXPECT_NE(farm.output.find("rank 2 silent for"), std::string::npos) << farm.output;
  EXPECT_NE(farm.output.find("rank 2 takes part again"), std::string::npos) << farm.output;
  EXPECT_EQ(farm.output.find("ending the job without it"), std::string::npos) << farm.output;
  ASSERT_TRUE(fs::exists(path("farm.exr"))) << farm.output;
  EXPECT_TRUE(exr_channels(path("farm.exr")) == exr_channels(path("local.exr"))) << "the image differs";
}

// The master is the one rank a farm cannot do without (it holds the image):
// stopped as its 3rd pass begins, its workers wait --farm-timeout for it,
// end the job with one line naming it and a non-zero status, and its last
// checkpoint resumes, on 2 ranks, to the uninterrupted image bit for bit.
TEST_F(FarmStallCli, StoppedMasterEndsTheJobAndItsCheckpointResumes) {
  const std::string args = kDoor + " -q --no-preview --res 64x48 --spp 32 --seed 3 --guide qtable";
  RunResult whole = run("render " + args + " -o " + path("whole.exr"));
  ASSERT_EQ(whole.exit_code, 0) << whole.output;
  const std::string ck = path("farm.ckpt");
  RunResult stopped = run_mpi_stopping(2, "0:pass:3", "render " + args + " --farm-timeout 2 --checkpoint " + ck +
                                                          " --checkpoint-every 0 -o " + path("stopped.exr"));
  EXPECT_NE(stopped.exit_code, 0) << stopped.output;
  const int pid = stopped_pid(stopped.output, 0);
  ASSERT_GT(pid, 0) << "the master did not stop\n" << stopped.output;
  EXPECT_TRUE(dies_soon(pid)) << "the stopped master outlived the job";
  EXPECT_NE(stopped.output.find("tessera: error: rank 1: rank 0 (the master) silent for"), std::string::npos)
      << stopped.output;
  ASSERT_TRUE(fs::exists(ck)) << stopped.output;
  RunResult resumed = run_mpi(2, "render " + args + " -o " + path("resumed.exr") + " --resume " + ck);
  ASSERT_EQ(resumed.exit_code, 0) << resumed.output;
  EXPECT_NE(resumed.output.find("resuming at"), std::string::npos) << resumed.output;
  EXPECT_TRUE(exr_channels(path("resumed.exr")) == exr_channels(path("whole.exr"))) << "the resumed image differs";
}

}  // namespace
}  // namespace tessera
