// --snapshot-every: the policy's parsing, and when SnapshotWriter writes
// (every N seconds of the render's clock, or at each power of two of spp
// reached at a pass end), with the files and CSV lines it leaves. The pass
// ends are made up here, so no timing is involved.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "../test_dir.h"
#include "render/renderer.h"
#include "render/snapshots.h"

namespace tessera {
namespace {

namespace fs = std::filesystem;

TEST(SnapshotPolicy, Parses) {
  SnapshotPolicy d = parse_snapshot_policy("doubling");
  EXPECT_TRUE(d.doubling);
  EXPECT_EQ(d.every_s, 0.0);
  EXPECT_TRUE(d.enabled());
  SnapshotPolicy s = parse_snapshot_policy("2.5");
  EXPECT_FALSE(s.doubling);
  EXPECT_EQ(s.every_s, 2.5);
  EXPECT_TRUE(s.enabled());
  EXPECT_EQ(parse_snapshot_policy("1e-3").every_s, 1e-3);
  EXPECT_FALSE(SnapshotPolicy{}.enabled());
}

TEST(SnapshotPolicy, RejectsNamingTheOption) {
  for (const char* bad : {"0", "-1", "2y", "", "nan", "inf", "Doubling", "double", "1s", "0x"}) {
    try {
      parse_snapshot_policy(bad);
      ADD_FAILURE() << "accepted '" << bad << "'";
    } catch (const std::runtime_error& e) {
      const std::string msg = e.what();
      EXPECT_NE(msg.find("--snapshot-every"), std::string::npos) << msg;
      EXPECT_NE(msg.find("'" + std::string(bad) + "'"), std::string::npos) << msg;
    }
  }
}

class SnapshotWriterTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = testing::fresh_test_dir("tessera_snap");
    so_far_.film = Film(4, 2);
    for (PixelAccum& p : so_far_.film.pixels) {
      p.n = 1;
      for (int c = 0; c < 3; ++c) p.sum[c] = p.sum_sq[c] = 1.0;
    }
  }
  void TearDown() override { fs::remove_all(dir_); }

  // A pass end at this many spp and seconds (of which `hooks` were spent in pass-end hooks).
  void pass_end(SnapshotWriter& w, uint32_t spp, double seconds, double hooks = 0.0, double est = -1.0) {
    so_far_.stats.spp = spp;
    so_far_.stats.seconds = seconds;
    so_far_.stats.pass_end_seconds = hooks;
    so_far_.stats.estimated_rel_mse = est;
    w.on_pass_end(so_far_);
  }
  std::vector<std::string> csv_lines() const {
    std::ifstream f(dir_ / "out-snapshots" / "snapshots.csv");
    std::vector<std::string> lines;
    for (std::string l; std::getline(f, l);) lines.push_back(l);
    return lines;
  }

  fs::path dir_;
  RenderResult so_far_;
};

TEST_F(SnapshotWriterTest, DoublingWritesAtEachPowerOfTwoReached) {
  SnapshotWriter w(parse_snapshot_policy("doubling"), (dir_ / "out.exr").string(), {});
  EXPECT_EQ(fs::path(w.directory()), dir_ / "out-snapshots");
  // Pass ends need not land on powers of two: 12 is none, 20 is the first
  // past 16, 28 none, 36 the first past 32.
  for (uint32_t spp : {1u, 2u, 4u, 8u, 12u, 20u, 28u, 36u}) pass_end(w, spp, spp * 0.01);
  std::vector<uint32_t> got;
  for (const SnapshotRecord& r : w.records()) got.push_back(r.spp);
  EXPECT_EQ(got, (std::vector<uint32_t>{1, 2, 4, 8, 20, 36}));
  for (uint32_t spp : got) {
    char name[64];
    std::snprintf(name, sizeof name, "out-%06uspp.exr", spp);
    EXPECT_TRUE(fs::exists(dir_ / "out-snapshots" / name)) << name;
  }
  EXPECT_FALSE(fs::exists(dir_ / "out-snapshots" / "out-000012spp.exr"));
  const std::vector<std::string> lines = csv_lines();
  ASSERT_EQ(lines.size(), 7u);
  EXPECT_EQ(lines[0], "file,spp,seconds,render_seconds,estimated_relmse");
  EXPECT_EQ(lines[5].rfind("out-000020spp.exr,20,", 0), 0u) << lines[5];
}

TEST_F(SnapshotWriterTest, SecondsPolicyUsesTheRenderClock) {
  SnapshotWriter w(parse_snapshot_policy("1"), (dir_ / "out.exr").string(), {});
  // Due when a second has passed since the last snapshot (or the start).
  const double seconds[] = {0.4, 1.0, 1.5, 2.1, 2.5, 3.2};
  for (uint32_t i = 0; i < 6; ++i) pass_end(w, i + 1, seconds[i], 0.25, 0.5 / (i + 1));
  ASSERT_EQ(w.records().size(), 3u);
  const SnapshotRecord* r = w.records().data();
  EXPECT_EQ(r[0].spp, 2u);
  EXPECT_EQ(r[1].spp, 4u);
  EXPECT_EQ(r[2].spp, 6u);
  EXPECT_EQ(r[1].seconds, 2.1);
  EXPECT_DOUBLE_EQ(r[1].render_seconds, 2.1 - 0.25);  // without the time spent in pass-end hooks
  EXPECT_EQ(r[1].estimated_rel_mse, 0.5 / 4);
  EXPECT_EQ(fs::path(r[2].file), dir_ / "out-snapshots" / "out-000006spp.exr");
  const std::vector<std::string> lines = csv_lines();
  ASSERT_EQ(lines.size(), 4u);
  EXPECT_EQ(lines[2], "out-000004spp.exr,4,2.100000,1.850000,0.125");
}

}  // namespace
}  // namespace tessera
