#include "worker/thread_guide_accumulators.h"

namespace tessera {

const TileSettings& ThreadGuideAccumulators::for_this_thread() {
  const GuideView& g = shared_.path.guide;
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

void ThreadGuideAccumulators::gather() {
  uint64_t* shared = shared_.path.guide.acc;
  for (const Local& local : locals_)
    for (size_t i = 0; i < local.block.size(); ++i) shared[i] += local.block[i];
  locals_.clear();
}

}  // namespace tessera
