#include "render/thread_guide_accumulators.h"

#include <algorithm>

#include "guidecache/neural/neural_training_log.h"
#include "render/neural_tile_targets.h"

namespace tessera {

const TileSettings& ThreadGuideAccumulators::for_this_thread() {
  const GuideView& g = shared_.path.guide;
  const bool neural = shared_.neural_log != nullptr && shared_.path.neural.params != nullptr;
  if (neural) {
    bool exists = false;
    Local& local = locals_.local(exists);
    if (!exists) {
      local.settings = shared_;
      local.targets.resize(neural_tile_capacity(shared_.path.neural));
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
  sink->tile = job.index;
  sink->rejected_nonfinite = sink->rejected_large = sink->dropped = 0;
  for (uint64_t& v : sink->mix_moments) v = 0;
  sink->mix_vertices = sink->mix_rejected = 0;
  sink->keep_prob = neural_tile_keep_prob(mine, job);
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
