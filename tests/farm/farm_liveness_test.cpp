// A silent rank in a farm inside one process (tests/farm/in_process_farm.h):
// a worker stalled at any point of a pass (before its first tiles, after it
// returned some, in the middle of the guide's learning rounds) is left out
// after the lease, and the farm still renders the local image, and folds the
// local guide, bit for bit; a stalled worker that wakes up takes part again
// with the master's guide; a worker that says hello late joins; a worker
// whose master is silent gives up.
#include <gtest/gtest.h>

#include <memory>
#include <string>

#include "in_process_farm.h"

namespace tessera {
namespace {

using testing::FarmGuide;
using testing::FarmHooks;
using testing::FarmRun;
using testing::FarmScene;
using testing::Gate;
using testing::door_ajar;
using testing::expect_same_counters;
using testing::films_identical;
using testing::render_farm;

// Long against a tile of this small image, short for a test.
constexpr double kLease = 1.0;

// 36 tiles: every rank gets some in every pass.
FarmScene small_door() { return FarmScene(door_ajar(96, 72)); }

// A pause hook that waits at `gate` the nth time a rank reaches `point`.
std::function<void(const char*)> stall_at(const std::string& point, int nth, Gate* gate) {
  auto seen = std::make_shared<int>(0);
  return [=](const char* reached) {
    if (point == reached && ++*seen == nth) gate->wait();
  };
}

struct Expected {
  RenderResult image;
  std::unique_ptr<Guide> guide;
};

Expected local_render(const FarmScene& fs, FarmGuide kind) {
  Expected e;
  e.guide = testing::make_farm_guide(fs, kind);
  e.image = render(fs.scene, fs.embree, fs.opt, e.guide.get());
  return e;
}

// The farm's image and counters are the local render's; so is the guide of
// every rank in `ranks_with_guide`.
void expect_local(const FarmRun& farm, const Expected& local, std::initializer_list<int32_t> ranks_with_guide,
                  const std::string& what) {
  EXPECT_TRUE(films_identical(farm.result.film, local.image.film)) << what << ": the image differs";
  expect_same_counters(farm.result.stats.counters, local.image.stats.counters);
  if (!local.guide) return;
  for (int32_t r : ranks_with_guide) {
    ASSERT_LT(size_t(r), farm.guides.size()) << what << ": the render failed";
    EXPECT_TRUE(farm.guides[r]->same_as(*local.guide)) << what << ": rank " << r << "'s guide differs";
  }
}

std::string guide_name(FarmGuide kind) {
  return kind == FarmGuide::None ? "none" : kind == FarmGuide::Table ? "table" : "neural";
}

// Rank 2 stalls at the nth `point` until the render is over, on a 3-rank
// farm; what the master printed comes back in *log.
FarmRun stall_until_the_end(const FarmScene& fs, FarmGuide kind, const std::string& point, int nth, std::string* log) {
  Gate gate;
  FarmHooks hooks;
  hooks.lease_s = kLease;
  hooks.worker_pause = {{}, {}, stall_at(point, nth, &gate)};
  hooks.after_finish = [&] { gate.open(); };
  ::testing::internal::CaptureStderr();
  FarmRun run;
  try {
    run = render_farm(fs, 3, kind, true, {}, hooks);
  } catch (const std::exception& e) {
    ADD_FAILURE() << e.what();
  }
  *log = ::testing::internal::GetCapturedStderr();
  return run;
}

// Stalled before it renders anything: its tiles go to the others, and it
// holds no learning, so the rounds go on without it.
TEST(FarmLiveness, WorkerStalledBeforeItsFirstTilesLeavesTheLocalImage) {
  FarmScene fs = small_door();
  for (FarmGuide kind : {FarmGuide::None, FarmGuide::Table, FarmGuide::Neural}) {
    const Expected local = local_render(fs, kind);
    std::string log;
    FarmRun farm = stall_until_the_end(fs, kind, "tiles", 1, &log);
    expect_local(farm, local, {0, 1}, guide_name(kind));
    EXPECT_NE(log.find("rank 2 silent for"), std::string::npos) << log;
    EXPECT_NE(log.find("tiles re-issued"), std::string::npos) << log;
    ASSERT_EQ(farm.silent.size(), 1u);
    EXPECT_EQ(farm.silent[0].rank, 2);
  }
}

// Stalled after it returned its first tiles: their pixels came, their
// learning did not; the master renders them again for it.
TEST(FarmLiveness, WorkerStalledAfterItsFirstResultIsRelearnedByTheMaster) {
  FarmScene fs = small_door();
  for (FarmGuide kind : {FarmGuide::Table, FarmGuide::Neural}) {
    const Expected local = local_render(fs, kind);
    std::string log;
    FarmRun farm = stall_until_the_end(fs, kind, "result", 1, &log);
    expect_local(farm, local, {0, 1}, guide_name(kind));
    EXPECT_NE(log.find("rank 0 relearns its"), std::string::npos) << log;
  }
}

// Stalled in the learning rounds after its tiles: a stand-in (the guide as
// the pass began, the worker's tiles, the rounds so far) takes its place.
// The network's 2nd round has one folded before it.
TEST(FarmLiveness, WorkerStalledInTheLearningRoundsIsStoodInFor) {
  FarmScene fs = small_door();
  for (auto [kind, nth] : {std::pair{FarmGuide::Table, 1}, std::pair{FarmGuide::Neural, 3}}) {
    const Expected local = local_render(fs, kind);
    std::string log;
    FarmRun farm = stall_until_the_end(fs, kind, "round", nth, &log);
    expect_local(farm, local, {0, 1}, guide_name(kind));
    EXPECT_NE(log.find(" during the guide's learning; rank 0 relearns its"), std::string::npos)
        << log;
  }
}

// A stalled worker that wakes up: what it sends about the pass it was left
// out of is ignored (its tiles were done by others), and from the next pass
// it takes part again with the master's guide, ending with the local one.
TEST(FarmLiveness, WorkerThatWakesUpTakesPartAgainWithTheMastersGuide) {
  FarmScene fs = small_door();
  fs.opt.spp = 24;  // passes of 1, 1, 2, 4, 8, 8 spp: it wakes as the 3rd begins
  for (FarmGuide kind : {FarmGuide::Table, FarmGuide::Neural}) {
    const Expected local = local_render(fs, kind);
    Gate gate;
    FarmHooks hooks;
    hooks.lease_s = kLease;
    hooks.worker_pause = {{}, {}, stall_at("tiles", 1, &gate)};
    auto passes = std::make_shared<int>(0);
    hooks.master_pause = [&, passes](const char*) {
      if (++*passes == 3) gate.open();
    };
    ::testing::internal::CaptureStderr();
    FarmRun farm = render_farm(fs, 3, kind, true, {}, hooks);
    const std::string log = ::testing::internal::GetCapturedStderr();
    expect_local(farm, local, {0, 1, 2}, guide_name(kind));
    EXPECT_NE(log.find("rank 2 takes part again"), std::string::npos) << log;
    EXPECT_TRUE(farm.silent.empty());
  }
}

// A worker that says hello only after the master started without it joins
// at the next pass, with the master's guide.
TEST(FarmLiveness, WorkerThatSaysHelloLateJoinsAtTheNextPass) {
  FarmScene fs = small_door();
  fs.opt.spp = 24;
  const Expected local = local_render(fs, FarmGuide::Table);
  Gate late;
  FarmHooks hooks;
  hooks.lease_s = kLease;  // the master waits this long for hellos
  hooks.start_gate = {nullptr, nullptr, &late};
  auto passes = std::make_shared<int>(0);
  hooks.master_pause = [&, passes](const char*) {
    if (++*passes == 2) late.open();
  };
  hooks.after_finish = [&] { late.open(); };
  ::testing::internal::CaptureStderr();
  FarmRun farm = render_farm(fs, 3, FarmGuide::Table, true, {}, hooks);
  const std::string log = ::testing::internal::GetCapturedStderr();
  expect_local(farm, local, {0, 1, 2}, "late hello");
  EXPECT_NE(log.find("rank 2 has not said hello"), std::string::npos) << log;
  EXPECT_NE(log.find("rank 2 said hello; it joins at the next pass"), std::string::npos) << log;
}

// The master holds the image: a worker that hears nothing from it (not even
// an answer to its pings) for the timeout gives up, naming it.
TEST(FarmLiveness, WorkerGivesUpOnASilentMaster) {
  FarmScene fs = small_door();
  InProcessHub hub(2);
  auto master_end = hub.endpoint(0), worker_end = hub.endpoint(1);
  FarmWorkerOptions options;
  options.timeout_s = 0.3;
  std::unique_ptr<Guide> guide;
  try {
    run_farm_worker(*worker_end, fs.embree, make_tile_settings(fs.opt, kSpecAll, false), guide, options);
    ADD_FAILURE() << "the worker should give up";
  } catch (const MasterSilent& e) {
    EXPECT_NE(std::string(e.what()).find("rank 0 (the master) silent for"), std::string::npos) << e.what();
  }
  // It said hello, then asked after the master before it gave up.
  Message m;
  ASSERT_TRUE(master_end->try_receive(&m, 1));
  EXPECT_EQ(m.tag, kTagHello);
  ASSERT_TRUE(master_end->try_receive(&m, 1));
  EXPECT_EQ(m.tag, kTagPing);
}

}  // namespace
}  // namespace tessera
