// The CPU backends' pass loop: this process's threads (a oneTBB arena) take
// tiles from the queue one at a time and render them with the backend's
// ray queries; each thread learns into its own copy of the guide's
// accumulators (render/thread_guide_accumulators.h), added up at end_pass.
// Embree (render/embree_backend.h) and the portable BVH
// (render/bvh_backend.h) differ only in render_one.
#pragma once

#include <tbb/task_arena.h>

#include <memory>
#include <optional>

#include "render/thread_guide_accumulators.h"
#include "render/tile_backend.h"

namespace tessera {

class CpuTileBackend : public TileBackend {
 public:
  void begin_pass(const TileSettings& settings) override;
  TileCounters render_tiles(TileQueue& queue, int32_t threads) override;
  void end_pass() override;

 protected:
  // One tile with the calling thread's settings (splats: null unless caustics are light-traced).
  virtual TileCounters render_one(const TileSettings& settings, const TileJob& job, TilePixels pixels,
                                  std::vector<Splat>* splats) const = 0;

 private:
  std::optional<ThreadGuideAccumulators> guide_acc_;
  std::unique_ptr<tbb::task_arena> arena_;  // kept across passes while the thread count stays
  int32_t arena_threads_ = 0;
};

}  // namespace tessera
