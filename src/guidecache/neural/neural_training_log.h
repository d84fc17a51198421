// The learning targets one process recorded in a pass for the neural guide,
// kept per tile: the CPU backends' threads add a tile's targets when they
// finish it (any order, any thread), and the guide takes them sorted by tile
// index, so that what it trains on, and in which order, does not depend on
// threads or on which rank rendered which tile.
#pragma once

#include <algorithm>
#include <cstdint>
#include <mutex>
#include <vector>

#include "guidecache/neural/neural_view.h"

namespace tessera {

struct NeuralTileTargets {
  uint32_t tile = 0;
  std::vector<NeuralTrainingSample> samples;
};

struct NeuralLogCounts {
  uint64_t rejected_nonfinite = 0, rejected_large = 0, dropped = 0;
  uint64_t mix_moments[kNeuralMixCandidates] = {};  // NeuralSampleSink's mixture statistics
  uint64_t mix_vertices = 0, mix_rejected = 0;
};

class NeuralTrainingLog {
 public:
  // Thread-safe. The sink's counters are added; its targets copied.
  void add_tile(const NeuralSampleSink& sink) {
    NeuralTileTargets t;
    t.tile = sink.tile;
    t.samples.assign(sink.data, sink.data + sink.count);
    std::lock_guard<std::mutex> lock(mutex_);
    counts_.rejected_nonfinite += sink.rejected_nonfinite;
    counts_.rejected_large += sink.rejected_large;
    counts_.dropped += sink.dropped;
    for (uint32_t k = 0; k < kNeuralMixCandidates; ++k) counts_.mix_moments[k] += sink.mix_moments[k];
    counts_.mix_vertices += sink.mix_vertices;
    counts_.mix_rejected += sink.mix_rejected;
    tiles_.push_back(std::move(t));
  }
  // The pass's tiles sorted by index, and its counts; the log is empty after.
  std::vector<NeuralTileTargets> take(NeuralLogCounts* counts) {
    std::lock_guard<std::mutex> lock(mutex_);
    std::vector<NeuralTileTargets> out = std::move(tiles_);
    tiles_.clear();
    *counts = counts_;
    counts_ = {};
    std::sort(out.begin(), out.end(), [](const NeuralTileTargets& a, const NeuralTileTargets& b) { return a.tile < b.tile; });
    return out;
  }

 private:
  std::mutex mutex_;
  std::vector<NeuralTileTargets> tiles_;
  NeuralLogCounts counts_;
};

}  // namespace tessera
