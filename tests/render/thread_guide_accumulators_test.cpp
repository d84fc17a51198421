// Thread-private guide accumulators: what learning adds through them and then
// gather() must equal, integer for integer, what the same targets add to the
// shared block with atomics, whatever thread did which update.
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <gtest/gtest.h>

#include <set>
#include <mutex>

#include "guidecache/table/guide_field.h"
#include "render/thread_guide_accumulators.h"

namespace tessera {
namespace {

GuideField make_field() { return GuideField(GuideConfig{}, Vec3(0.f), Vec3(1.f), 4, 10.f); }

// Deterministic pseudo-random learning targets: update k goes to (entry, value).
void record_update(const GuideView& g, uint32_t k) {
  const uint32_t entry = (k * 2654435761u) % g.stride;
  const Float target = static_cast<Float>((k * 40503u) % 1000u) * 0.01f;
  guide_record(g, 0, entry, target);
  if (k % 97 == 0) guide_record(g, 0, entry, -1.f);  // rejected and counted
  guide_record_normal(g, 0, Vec3(0.f, 0.f, 1.f));
}

TEST(ThreadGuideAccumulators, GatherEqualsTheSharedAtomicBlock) {
  constexpr uint32_t kUpdates = 20000;
  GuideField shared_field = make_field(), private_field = make_field();

  const GuideView shared_view = shared_field.view();
  tbb::parallel_for(0u, kUpdates, [&](uint32_t k) { record_update(shared_view, k); });

  TileSettings settings;
  settings.path.guide = private_field.view();
  ThreadGuideAccumulators acc(settings);
  std::mutex mutex;
  std::set<const uint64_t*> blocks;
  tbb::task_arena arena(4);
  arena.execute([&] {
    tbb::parallel_for(0u, kUpdates, [&](uint32_t k) {
      const GuideView& mine = acc.for_this_thread().path.guide;
      EXPECT_TRUE(mine.acc_private);
      EXPECT_NE(mine.acc, settings.path.guide.acc);  // never the shared block
      {
        std::lock_guard<std::mutex> lock(mutex);
        blocks.insert(mine.acc);
      }
      record_update(mine, k);
    });
  });
  // Nothing reaches the shared block before gather().
  for (uint64_t v : private_field.accumulators()) ASSERT_EQ(v, 0u);
  acc.gather();

  EXPECT_GE(blocks.size(), 1u);
  EXPECT_EQ(private_field.accumulators(), shared_field.accumulators());
  const GuideView v = private_field.view();
  EXPECT_EQ(v.rejected[0], (kUpdates + 96) / 97);  // the rejections went through the copies too
}

TEST(ThreadGuideAccumulators, WithoutAGuideTheSettingsAreTheSharedOnes) {
  TileSettings settings;
  settings.seed = 7;
  ThreadGuideAccumulators acc(settings);
  EXPECT_EQ(acc.for_this_thread().seed, 7u);
  EXPECT_EQ(acc.for_this_thread().path.guide.acc, nullptr);
  acc.gather();  // nothing to add
}

}  // namespace
}  // namespace tessera
