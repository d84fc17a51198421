#include "worker/thread_guide_accumulators.h"

#include <algorithm>

#include "guidecache/neural_training_log.h"

namespace tessera {

const TileSettings& ThreadGuideAccumulators::for_this_thread() {
  const GuideView& g = shared_.path.guide;
  const bool neural = shared_.neural_log != nullptr && shared_.path.neural.params != nullptr;
  if (neural) {
    bool exists = false;
    Local& local = locals_.local(exists);
    if (!exists) {
      local.settings = shared_;
      // Room for four times the targets a tile keeps on average: a tile
      // that keeps more drops the rest (counted, and the same on every run;
      // the dropped are the tile's last pixels', so it should be rare).
      local.targets.resize(4 * size_t(std::max(shared_.path.neural.tile_targets, 1u)) + 64);
      local.sink.data = local.targets.data();
      local.sink.capacity = static_cast<uint32_t>(local.targets.size());
      local.settings.path.neural.sink = &local.sink;
    }
    return local.settings;
  }
  if (g.acc == nullptr || g.acc_words == 0) return shared_;
  bool exists = false;
  Local& local = locals_.local(exists);
  if (!exists) {
    local.block.assign(g.acc_words, 0);
    local.settings = shared_;
    GuideView& mine = local.settings.path.guide;
    uint64_t* base = local.block.data();
    mine.acc = base;
    mine.acc_normal = base + (g.acc_normal - g.acc);
    mine.rejected = base + (g.rejected - g.acc);
    mine.acc_private = true;
  }
  return local.settings;
}

void ThreadGuideAccumulators::begin_tile(const TileSettings& mine, const TileJob& job) const {
  NeuralSampleSink* sink = mine.path.neural.sink;
  if (!sink) return;
  sink->count = 0;
  sink->seen = 0;
  sink->tile = job.index;
  sink->rejected_nonfinite = sink->rejected_large = sink->dropped = 0;
  // A learning sample offers a direction target per path vertex (about
  // five on the shipped scenes with guided roulette) and, where light
  // selection is learned, a light target per next-event estimate too; the
  // tile keeps tile_targets of them on average. Which samples learn follows
  // the schedule (by index).
  const double per_sample = mine.path.neural.lights > 0 ? 10.0 : 5.0;
  uint64_t learning = 0;
  for (uint32_t si = job.sample_begin; si < job.sample_end; ++si) learning += mine.learn.learns(si) ? 1 : 0;
  const double offered = per_sample * double(job.x1 - job.x0) * double(job.y1 - job.y0) * double(learning);
  sink->keep_prob = offered > 0.0 ? static_cast<Float>(std::min(1.0, mine.path.neural.tile_targets / offered)) : 1.f;
}

void ThreadGuideAccumulators::end_tile(const TileSettings& mine) const {
  if (mine.path.neural.sink && mine.neural_log) mine.neural_log->add_tile(*mine.path.neural.sink);
}

void ThreadGuideAccumulators::gather() {
  uint64_t* shared = shared_.path.guide.acc;
  if (shared == nullptr) {
    locals_.clear();
    return;
  }
  for (const Local& local : locals_)
    for (size_t i = 0; i < local.block.size(); ++i) shared[i] += local.block[i];
  locals_.clear();
}

}  // namespace tessera
