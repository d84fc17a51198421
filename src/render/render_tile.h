// What a tile is rendered with: the settings every tile of a render shares,
// the counters a tile returns and where its pixel accumulators are (the tile
// itself, TileJob, is in render/tile_job.h). Rendering one is a pure
// function of (scene, job, seed); each backend (render/tile_backend.h) does
// it with its own ray queries.
#pragma once

#include <algorithm>
#include <cstdint>
#include <vector>

#include "kernels/effects.h"
#include "integrator/path_state.h"
#include "kernels/sampler.h"
#include "render/film.h"
#include "render/tile_job.h"

namespace tessera {

// Which samples train the guide, by sample index (so it is the same on every
// thread and rank): every sample below all_spp, then every `every`-th (0:
// none). Learning costs about as much per vertex as guided sampling; past the
// first passes the field changes little, so most samples just use it
// (measured at equal time: every 8th and every 4th gave the same error, every
// 8th is faster).
//
// With `taper`, the gap between learning samples doubles each time the sample
// index doubles past 16 * every (128 by default; all_spp if that is larger):
// each doubling of a render adds kTaperLearnPerDoubling learning samples per
// pixel. The field keeps being refined, while the share of samples that pay
// for learning, 1/every forever without the taper, falls towards zero in long
// renders.
struct GuideLearnSchedule {
  static constexpr uint32_t kTaperLearnPerDoubling = 8;
  uint32_t all_spp = 16;
  uint32_t every = 8;
  bool taper = true;
  // Gap between learning sample indices around sample_index (past all_spp).
  TESSERA_HOST_DEVICE uint64_t period(uint32_t sample_index) const {
    const uint64_t start = std::max<uint64_t>(uint64_t{2 * kTaperLearnPerDoubling} * every, all_spp);
    if (!taper || sample_index < start) return every;
    uint32_t doublings = 1;
    while ((start << doublings) <= sample_index) ++doublings;
    return uint64_t{every} << doublings;
  }
  TESSERA_HOST_DEVICE bool learns(uint32_t sample_index) const {
    return sample_index < all_spp || (every > 0 && sample_index % period(sample_index) == 0);
  }
};

class NeuralTrainingLog;

struct TileSettings {
  uint64_t seed = 0;
  SamplerSetup sampler;  // its seed is `seed`
  PathSettings path;
  GuideLearnSchedule learn;
  uint32_t specialisation = kSpecAll;
  // The neural guide's learning targets go here (via each thread's sink in
  // path.neural; render/thread_guide_accumulators.h). Null: not recorded.
  NeuralTrainingLog* neural_log = nullptr;
};

struct TileCounters {
  PathCounters path;
  uint64_t samples = 0;
  uint64_t zero_radiance = 0;    // samples whose estimate is exactly black
  uint64_t rejected_nonfinite = 0;  // NaN/Inf estimates replaced by 0 (and counted)
  uint64_t rejected_negative = 0;

  void add(const TileCounters& o) {
    path.rays += o.path.rays;
    path.shadow_rays += o.path.shadow_rays;
    path.vertices += o.path.vertices;
    path.interface_skips += o.path.interface_skips;
    path.guidable_vertices += o.path.guidable_vertices;
    path.guided_samples += o.path.guided_samples;
    path.guide_withheld_vertices += o.path.guide_withheld_vertices;
    path.guide_updates += o.path.guide_updates;
    path.guided_roulette += o.path.guided_roulette;
    path.nee_skipped += o.path.nee_skipped;
    path.medium_vertices += o.path.medium_vertices;
    path.light_paths += o.path.light_paths;
    path.light_splats += o.path.light_splats;
    path.caustic_emission_skipped += o.path.caustic_emission_skipped;
    path.neural_sites_reused += o.path.neural_sites_reused;
    path.untraceable_rays += o.path.untraceable_rays;
    samples += o.samples;
    zero_radiance += o.zero_radiance;
    rejected_nonfinite += o.rejected_nonfinite;
    rejected_negative += o.rejected_negative;
  }
};

// Where a tile's pixel accumulators live: pixel (x, y) of the job is at
// origin[(y - y0) * stride + (x - x0)]. A local render points into the
// image's film; a farm worker into the tile's own buffer.
struct TilePixels {
  PixelAccum* origin = nullptr;
  int32_t stride = 0;
  PixelAccum& at(const TileJob& job, int32_t x, int32_t y) const {
    return origin[static_cast<size_t>(y - job.y0) * stride + (x - job.x0)];
  }
};

// A tile of the image's film.
inline TilePixels film_tile(Film& film, const TileJob& job) { return {&film.at(job.x0, job.y0), film.width}; }

// Light paths a job traces: one per camera sample when caustics are light-traced.
inline uint64_t job_light_paths(const TileSettings& settings, const TileJob& job) {
  if (!settings.path.light_traced_caustics) return 0;
  return static_cast<uint64_t>(job.x1 - job.x0) * static_cast<uint64_t>(job.y1 - job.y0) *
         (job.sample_end - job.sample_begin);
}

}  // namespace tessera
