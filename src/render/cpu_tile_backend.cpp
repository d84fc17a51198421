#include "render/cpu_tile_backend.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <stdexcept>

namespace tessera {

void CpuTileBackend::begin_pass(const TileSettings& settings) { guide_acc_.emplace(settings); }

TileCounters CpuTileBackend::render_tiles(TileQueue& queue, int32_t threads) {
  if (!guide_acc_) throw std::logic_error("CpuTileBackend: render_tiles outside a pass");
  threads = std::max(1, threads);
  if (!arena_ || arena_threads_ != threads) {
    arena_ = std::make_unique<tbb::task_arena>(threads);
    arena_threads_ = threads;
  }
  // Counters per thread slot, summed in slot order (integers: the order does not matter anyway).
  std::vector<TileCounters> counters(static_cast<size_t>(threads));
  std::atomic<bool> failed{false};  // a tile threw: the other threads stop taking tiles
  arena_->execute([&] {
    tbb::parallel_for(0, threads, [&](int32_t slot) {
      try {
        const TileSettings& settings = guide_acc_->for_this_thread();
        const bool light_paths = settings.path.light_traced_caustics;
        TileTask task;
        while (!failed) {
          queue.between_tiles();
          if (!queue.take(&task)) break;
          std::vector<Splat> splats;
          guide_acc_->begin_tile(settings, task.job);
          const TileCounters tc = render_one(settings, task.job, task.pixels, light_paths ? &splats : nullptr);
          guide_acc_->end_tile(settings);
          counters[static_cast<size_t>(slot)].add(tc);
          queue.done(task, tc.samples, std::move(splats));
        }
      } catch (...) {
        failed = true;
        throw;
      }
    });
  });
  TileCounters sum;
  for (const TileCounters& c : counters) sum.add(c);
  return sum;
}

void CpuTileBackend::end_pass() {
  if (guide_acc_) guide_acc_->gather();
  guide_acc_.reset();
}

}  // namespace tessera
