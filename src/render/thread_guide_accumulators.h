// Thread-private guide accumulators for one pass on the CPU.
//
// Every learning vertex adds a dozen or more integers to the guide's
// accumulators. With one block shared by all threads those are atomic adds,
// and they were half of what learning cost (door-ajar, every sample learning:
// 3.73 s with atomics, 3.16 s with these copies, 2.93 s without learning). Here
// each thread that renders tiles adds plainly into its own copy of the block,
// and gather() adds the copies into the shared block when the pass is done.
// Integer sums do not depend on order, so the field learns exactly the same
// numbers for any thread count, as with the shared block.
//
// For the neural guide each thread has a sink for one tile's learning
// targets instead: begin_tile() empties it, end_tile() hands the tile's
// targets to the pass's training log (guidecache/neural/neural_training_log.h).
#pragma once

#include <tbb/enumerable_thread_specific.h>

#include <cstdint>
#include <vector>

#include "render/render_tile.h"

namespace tessera {

class ThreadGuideAccumulators {
 public:
  // `settings` are the pass's; their guide view's block is the shared one
  // (no guide, or no block: every thread gets `settings` as they are).
  explicit ThreadGuideAccumulators(const TileSettings& settings) : shared_(settings) {}

  // The settings for tiles rendered by the calling thread: its guide view
  // points into the thread's own copy of the block.
  const TileSettings& for_this_thread();

  // Adds every thread's copy into the shared block. Call once, after the
  // pass's tiles are done and before the block is reduced or folded.
  void gather();

  // Around each tile, with the settings for_this_thread() gave.
  void begin_tile(const TileSettings& mine, const TileJob& job) const;
  void end_tile(const TileSettings& mine) const;

 private:
  struct Local {
    TileSettings settings;
    std::vector<uint64_t> block;
    std::vector<NeuralTrainingSample> targets;
    NeuralSampleSink sink;
  };
  TileSettings shared_;
  tbb::enumerable_thread_specific<Local> locals_;
};

}  // namespace tessera
