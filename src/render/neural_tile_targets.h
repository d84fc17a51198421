// How many of a tile's learning targets the neural guide keeps, shared by
// the CPU backends (render/thread_guide_accumulators.h) and the device
// backend (render/device_backend.h), so that both keep the same ones.
#pragma once

#include <algorithm>
#include <cstdint>

#include "render/render_tile.h"

namespace tessera {

// Samples of the job that learn (by the schedule, by index).
inline uint32_t job_learning_samples(const GuideLearnSchedule& learn, const TileJob& job) {
  uint32_t n = 0;
  for (uint32_t si = job.sample_begin; si < job.sample_end; ++si) n += learn.learns(si) ? 1 : 0;
  return n;
}

// The probability a target of the tile is kept (NeuralSampleSink::keep_prob).
// A learning sample offers a direction target per path vertex (about five
// on the shipped scenes with guided roulette) and, where light selection is
// learned, a light target per next-event estimate too; the tile keeps
// tile_targets of them on average.
inline Float neural_tile_keep_prob(const TileSettings& settings, const TileJob& job) {
  const double per_sample = settings.path.neural.lights > 0 ? 10.0 : 5.0;
  const double offered = per_sample * double(job.x1 - job.x0) * double(job.y1 - job.y0) *
                         double(job_learning_samples(settings.learn, job));
  return offered > 0.0 ? static_cast<Float>(std::min(1.0, settings.path.neural.tile_targets / offered)) : 1.f;
}

// Targets a tile keeps at most: four times its average, so that a tile
// that keeps more drops the rest (counted, the same on every run; the
// dropped are the tile's last pixels', so it should be rare).
inline uint32_t neural_tile_capacity(const NeuralGuideView& view) {
  return 4 * std::max(view.tile_targets, 1u) + 64;
}

}  // namespace tessera
