// The farm end to end under mpirun: the same EXR as a local run for 1, 2
// and 3 ranks; a render killed mid-way and resumed (on another number of
// ranks) equals an uninterrupted one; bad checkpoints and scenes give one
// clear error, a non-zero exit, and leave existing outputs alone.
#include <OpenEXR/ImfArray.h>
#include <OpenEXR/ImfChannelList.h>
#include <OpenEXR/ImfFrameBuffer.h>
#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfInputFile.h>
#include <gtest/gtest.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <regex>
#include <string>

#include "../test_dir.h"
#include "../cli_run.h"
#include "../exr_read.h"
#include "../json_read.h"
#include "../render/render_helpers.h"

namespace tessera {
namespace {

namespace fs = std::filesystem;
using testing::run;
using testing::run_mpi;
using testing::run_shell;
using testing::RunResult;
using testing::exr_channels;
using testing::json_number;
using testing::read_text;

class FarmCliTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = testing::fresh_test_dir("tessera_farm");
  }
  void TearDown() override { fs::remove_all(dir_); }
  std::string path(const std::string& name) const { return (dir_ / name).string(); }
  fs::path dir_;
};

const std::string kDoor = testing::source_dir() + "/scenes/door-ajar.pbrt";

TEST_F(FarmCliTest, MpirunWritesTheSameExrAsTheLocalRun) {
  const std::string args = kDoor + " -q --no-preview --res 64x48 --spp 10 --seed 3";
  RunResult local = run("render " + args + " -o " + path("local.exr") + " --stats " + path("local.json"));
  ASSERT_EQ(local.exit_code, 0) << local.output;
  const std::vector<float> expected = exr_channels(path("local.exr"));
  for (int ranks : {1, 2, 3}) {
    const std::string exr = path("farm" + std::to_string(ranks) + ".exr"), js = path("farm.json");
    RunResult farm = run_mpi(ranks, "render " + args + " -o " + exr + " --stats " + js);
    ASSERT_EQ(farm.exit_code, 0) << farm.output;
    EXPECT_TRUE(exr_channels(exr) == expected) << ranks << " ranks: the image differs from the local run";
    const std::string stats = read_text(js), local_stats = read_text(path("local.json"));
    for (const char* key : {"paths", "rays", "shadow_rays", "guide_updates"})
      EXPECT_EQ(json_number(stats, key), json_number(local_stats, key)) << key << ", " << ranks << " ranks";
    EXPECT_EQ(json_number(stats, "ranks"), double(ranks));
    if (ranks > 1) {
      EXPECT_GT(json_number(stats, "guide_syncs"), 0.0);
    }
  }
}

// The neural guide under mpirun: gradients summed in fixed point across
// ranks, the same Adam steps everywhere: the image of 1, 2 and 3 ranks is
// the local run's, bit for bit, and so is the saved network.
TEST_F(FarmCliTest, MpirunNeuralGuideWritesTheSameExrAndNetworkAsTheLocalRun) {
  const std::string args = kDoor + " -q --no-preview --res 48x36 --spp 10 --seed 3 --guide neural --neural-width 16 "
                                   "--neural-steps 4";
  RunResult local = run("render " + args + " -o " + path("local.exr") + " --guide-out " + path("local.nguide"));
  ASSERT_EQ(local.exit_code, 0) << local.output;
  const std::vector<float> expected = exr_channels(path("local.exr"));
  const std::string expected_net = read_text(path("local.nguide"));
  ASSERT_FALSE(expected_net.empty());
  for (int ranks : {1, 2, 3}) {
    const std::string exr = path("farm" + std::to_string(ranks) + ".exr"), js = path("farm.json");
    const std::string net = path("farm" + std::to_string(ranks) + ".nguide");
    RunResult farm = run_mpi(ranks, "render " + args + " -o " + exr + " --stats " + js + " --guide-out " + net);
    ASSERT_EQ(farm.exit_code, 0) << farm.output;
    EXPECT_TRUE(exr_channels(exr) == expected) << ranks << " ranks: the image differs from the local run";
    EXPECT_TRUE(read_text(net) == expected_net) << ranks << " ranks: the saved network differs";
    const std::string stats = read_text(js);
    EXPECT_GT(json_number(stats, "guide_neural_steps"), 0.0);
    if (ranks > 1) {
      EXPECT_GT(json_number(stats, "guide_syncs"), 4.0) << "a round per Adam step";
    }
  }
}

// Each rank picks its own backend (mpirun's colon syntax gives ranks their
// own arguments): a BVH rank and an emulated-device rank write the local
// BVH render's image bit for bit, and the stats name both.
TEST_F(FarmCliTest, RanksWithDifferentBackendsWriteTheLocalImage) {
  const std::string args = kDoor + " -q --no-preview --res 64x48 --spp 10 --seed 3";
  RunResult local = run("render " + args + " --backend bvh -o " + path("local.exr"));
  ASSERT_EQ(local.exit_code, 0) << local.output;
  const std::string exr = path("mixed.exr"), js = path("mixed.json");
  const std::string rank = std::string(TESSERA_BINARY) + " render " + args + " -o " + exr + " --stats " + js;
  RunResult farm = run_shell("OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 mpirun --oversubscribe -np 1 " +
                             rank + " --backend bvh : -np 1 " + rank + " --backend emulated-device 2>&1");
  ASSERT_EQ(farm.exit_code, 0) << farm.output;
  EXPECT_TRUE(exr_channels(exr) == exr_channels(path("local.exr"))) << "the mixed farm's image differs from the local one";
  EXPECT_NE(read_text(js).find("\"backend\": \"bvh+emulated-device\""), std::string::npos) << read_text(js);
}

// Slow (a whole render, a killed one and an mpirun resume; a ctest test of
// its own): the render must be long enough to be killed after its first pass.
TEST_F(FarmCliTest, KilledRenderResumesBitIdenticallyOnOtherRankCounts) {
  const std::string args = kDoor + " -q --no-preview --res 128x96 --spp 160 --seed 4";
  RunResult whole = run("render " + args + " -o " + path("whole.exr"));
  ASSERT_EQ(whole.exit_code, 0) << whole.output;
  // Checkpoint after every pass; SIGKILL shortly after the first one.
  const std::string ck = path("render.ckpt");
  RunResult killed = run_shell(std::string("(") + TESSERA_BINARY + " render " + args + " -o " + path("killed.exr") +
                               " --checkpoint " + ck + " --checkpoint-every 0 & P=$!; while [ ! -f " + ck +
                               " ]; do sleep 0.01; done; sleep 0.3; kill -9 $P; wait $P; echo killed=$?)");
  ASSERT_NE(killed.output.find("killed=137"), std::string::npos) << "the render finished before it was killed: " << killed.output;
  EXPECT_FALSE(fs::exists(path("killed.exr")));
  RunResult resumed = run_mpi(2, "render " + args + " -o " + path("resumed.exr") + " --resume " + ck);
  ASSERT_EQ(resumed.exit_code, 0) << resumed.output;
  std::smatch m;
  ASSERT_TRUE(std::regex_search(resumed.output, m, std::regex("resuming at ([0-9]+) spp"))) << resumed.output;
  EXPECT_LT(std::stoi(m[1]), 160);
  EXPECT_TRUE(exr_channels(path("resumed.exr")) == exr_channels(path("whole.exr")));
}

// Slow (waits out its 3 s + 2 s of signal timing, then resumes; a ctest
// test of its own, mostly asleep while the others run).
// Ctrl-C to mpirun (Open MPI sends every rank SIGCONT, SIGTERM
// odls_base_sigkill_timeout seconds later, 5 here, and SIGKILL as long
// again): the master stops the farm after the pass under way and writes the
// image so far and its checkpoint; resumed on another rank count and with another --spp, it ends
// as an uninterrupted render would. The scene is drawn with zsobol, whose
// epoch --spp must not change for the resume to be accepted.
TEST_F(FarmCliTest, InterruptedFarmWritesTheImageSoFarAndResumes) {
  const std::string args = kDoor + " -q --no-preview --res 64x48 --seed 5";
  const std::string ck = path("farm.ckpt");
  RunResult interrupted = run_shell(
      "OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 mpirun --oversubscribe --mca odls_base_sigkill_timeout 5 -np 2 " +
      std::string(TESSERA_BINARY) + " render " + args + " --time 120 -o " + path("interrupted.exr") + " --stats " +
      path("interrupted.json") + " --checkpoint " + ck + " --sampler zsobol --threads 1 2>&1 & P=$!; sleep 3; kill -INT $P; " +
      "sleep 2; test -f " + path("interrupted.json") + " && echo written-early; wait $P; echo done=$?");
  ASSERT_NE(interrupted.output.find("done="), std::string::npos) << interrupted.output;
  // Every rank gets the signal; the farm says once that it is stopping.
  const std::string say = "writing the image so far";
  const size_t first = interrupted.output.find(say);
  EXPECT_NE(first, std::string::npos) << interrupted.output;
  EXPECT_EQ(interrupted.output.find(say, first + 1), std::string::npos) << interrupted.output;
  // Open MPI sends the ranks SIGCONT at once and SIGTERM only after the kill
  // timeout (5 s here): the ranks stop on the SIGCONT, so the image is
  // written well before the SIGTERM.
  EXPECT_NE(interrupted.output.find("written-early"), std::string::npos) << interrupted.output;
  ASSERT_TRUE(fs::exists(path("interrupted.exr"))) << interrupted.output;
  const std::string stats = read_text(path("interrupted.json"));
  EXPECT_NE(stats.find("\"stop_reason\": \"interrupted\""), std::string::npos) << stats;
  const int spp = static_cast<int>(json_number(stats, "spp"));
  EXPECT_GT(spp, 0);
  const std::string more = " --sampler zsobol --spp " + std::to_string(spp + 16);
  RunResult resumed = run_mpi(3, "render " + args + more + " -o " + path("resumed.exr") + " --resume " + ck);
  ASSERT_EQ(resumed.exit_code, 0) << resumed.output;
  RunResult whole = run("render " + args + more + " -o " + path("whole.exr"));
  ASSERT_EQ(whole.exit_code, 0) << whole.output;
  EXPECT_TRUE(exr_channels(path("resumed.exr")) == exr_channels(path("whole.exr")));
}

// A worker signalled alone (as a scheduler may signal one node first): it
// tells the master with its next tile request, and the master stops the
// whole farm after the pass and writes the image so far. A worker that kept
// the signal to itself would render on until --time runs out.
TEST_F(FarmCliTest, SignalledWorkerStopsTheWholeFarm) {
  const std::string out = path("worker-signalled.json");
  RunResult r = run_shell(
      "OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 mpirun --oversubscribe -np 2 " +
      std::string(TESSERA_BINARY) + " render " + kDoor + " -q --no-preview --res 64x48 --seed 5 --time 60 --threads 1 -o " +
      path("worker-signalled.exr") + " --stats " + out + " & P=$!; sleep 3; " +
      // Only this test's ranks (their command line names its output): ctest
      // runs other farms beside it.
      "for p in $(pgrep -f 'tessera render.*" + out + "'); do tr '\\0' '\\n' < /proc/$p/environ 2>/dev/null | " +
      "grep -qx OMPI_COMM_WORLD_RANK=1 && kill -TERM $p; done; " +
      "for i in $(seq 1 50); do test -f " + out + " && break; sleep 0.2; done; test -f " + out +
      " && echo written-within-10s; wait $P; echo done=$?");
  ASSERT_NE(r.output.find("done="), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("written-within-10s"), std::string::npos) << r.output;
  const std::string stats = read_text(out);
  EXPECT_NE(stats.find("\"stop_reason\": \"interrupted\""), std::string::npos) << stats;
}

// Slow (one run of the binary per bad checkpoint, and mpirun; a ctest test of its own).
TEST_F(FarmCliTest, BadCheckpointsAreRefusedAndLeaveOutputsAlone) {
  const std::string args = kDoor + " -q --no-preview --res 32x24 --spp 4 --seed 4";
  const std::string ck = path("good.ckpt");
  ASSERT_EQ(run("render " + args + " -o " + path("a.exr") + " --checkpoint " + ck).exit_code, 0);
  const std::string bytes = read_text(ck);
  std::ofstream(path("truncated.ckpt"), std::ios::binary) << bytes.substr(0, bytes.size() / 2);
  std::string flipped = bytes;
  flipped[flipped.size() * 3 / 4] ^= 0x5a;
  std::ofstream(path("flipped.ckpt"), std::ios::binary) << flipped;
  std::ofstream(path("trailing.ckpt"), std::ios::binary) << bytes << "trailing garbage";
  // The payload size field (after the 19-byte magic, version, scene and
  // options fingerprints) claiming 512 GiB: refused before anything is allocated.
  std::string huge = bytes;
  const uint64_t claimed = uint64_t(1) << 39;
  std::memcpy(&huge[19 + 4 + 8 + 8], &claimed, sizeof claimed);
  std::ofstream(path("huge.ckpt"), std::ios::binary) << huge;
  std::ofstream(path("out.exr")) << "a good image";
  // The same scene through another pixel filter: the same geometry, other pixels.
  std::ofstream(path("door-box.pbrt")) << "PixelFilter \"box\"\n" << read_text(testing::source_dir() + "/scenes/door-ajar.pbrt");

  struct Case {
    std::string args, expect;
    int ranks;
  } cases[] = {
      {args + " --resume " + path("truncated.ckpt"), "truncated", 1},
      {args + " --resume " + path("flipped.ckpt"), "checksum", 2},
      {args + " --resume " + path("trailing.ckpt"), "bytes after its end", 1},
      {args + " --resume " + path("huge.ckpt"), "truncated checkpoint (", 1},
      {args + " --resume " + path("missing.ckpt"), "cannot open", 2},
      {kDoor + " -q --no-preview --res 32x24 --spp 4 --seed 5 --resume " + ck, "other render options", 1},
      {path("door-box.pbrt") + " -q --no-preview --res 32x24 --spp 4 --seed 4 --resume " + ck, "other render options", 1},
      {testing::source_dir() + "/scenes/cornell-box.pbrt -q --res 32x24 --spp 4 --seed 4 --resume " + ck,
       "another scene", 2},
  };
  for (const Case& c : cases) {
    RunResult r = c.ranks == 1 ? run("render " + c.args + " -o " + path("out.exr"))
                               : run_mpi(c.ranks, "render " + c.args + " -o " + path("out.exr"));
    EXPECT_NE(r.exit_code, 0) << r.output;
    EXPECT_NE(r.output.find("error: --resume"), std::string::npos) << r.output;
    EXPECT_NE(r.output.find(c.expect), std::string::npos) << r.output;
    EXPECT_EQ(read_text(path("out.exr")), "a good image");
  }
}

// Scenes that made Embree abort every rank (issue 48): a camera whose rays
// start beyond the tracer's reach is refused on the master in one line and
// the farm ends cleanly; a scene in a medium thin enough to scatter rays
// beyond it renders the local image, the refused rays counted alike.
TEST_F(FarmCliTest, RaysBeyondTheTracersReachNeitherAbortNorDiffer) {
  const std::string head = "LookAt 0 0 -5  0 0 0  0 1 0\n";
  const std::string world =
      "Film \"rgb\" \"integer xresolution\" [ 16 ] \"integer yresolution\" [ 12 ]\nWorldBegin\n"
      "LightSource \"point\" \"rgb I\" [ 10 10 10 ] \"point3 from\" [ 0 0 -2 ]\n"
      "Shape \"trianglemesh\" \"point3 P\" [ -10 -10 0  10 -10 0  10 10 0  -10 10 0 ] \"integer indices\" [ 0 1 2 0 2 3 ]\n";
  std::ofstream(path("lens.pbrt")) << head << "Camera \"perspective\" \"float lensradius\" [ 2e18 ]\n" << world;
  RunResult r = run_mpi(3, "render " + path("lens.pbrt") + " -q -o " + path("lens.exr"));
  EXPECT_NE(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("lens.pbrt:2: the camera's rays start at ("), std::string::npos) << r.output;
  EXPECT_EQ(r.output.find("ray.valid"), std::string::npos) << r.output;  // Embree's assertion
  EXPECT_EQ(r.output.find("signal"), std::string::npos) << r.output;     // mpirun on a rank that aborted
  EXPECT_FALSE(fs::exists(path("lens.exr")));

  std::ofstream(path("thin.pbrt")) << "MakeNamedMedium \"thin\" \"string type\" \"homogeneous\" \"rgb sigma_a\" [ 0 0 0 ] "
                                      "\"rgb sigma_s\" [ 1e-18 1e-18 1e-18 ]\nMediumInterface \"\" \"thin\"\n"
                                   << head << "Camera \"perspective\" \"float fov\" [ 90 ]\n"
                                   << std::regex_replace(world, std::regex("WorldBegin\n"), "WorldBegin\nMediumInterface \"thin\"\n");
  const std::string args = path("thin.pbrt") + " -q --no-preview --spp 4 --seed 2";
  RunResult local = run("render " + args + " -o " + path("local.exr") + " --stats " + path("local.json"));
  ASSERT_EQ(local.exit_code, 0) << local.output;
  RunResult farm = run_mpi(3, "render " + args + " -o " + path("farm.exr") + " --stats " + path("farm.json"));
  ASSERT_EQ(farm.exit_code, 0) << farm.output;
  EXPECT_TRUE(exr_channels(path("farm.exr")) == exr_channels(path("local.exr")));
  const double refused = json_number(read_text(path("local.json")), "untraceable_rays");
  EXPECT_GT(refused, 0.0);
  EXPECT_EQ(json_number(read_text(path("farm.json")), "untraceable_rays"), refused);
}

TEST_F(FarmCliTest, MissingSceneStopsEveryRank) {
  RunResult r = run_mpi(3, "render " + path("nope.pbrt") + " -q -o " + path("x.exr"));
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.output.find("nope.pbrt:1: cannot open scene file"), std::string::npos) << r.output;
  EXPECT_FALSE(fs::exists(path("x.exr")));
}

}  // namespace
}  // namespace tessera
