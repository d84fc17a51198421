// The local render loop: passes of samples per pixel over all tiles (oneTBB).
// Between passes is where later work (guide updates, farm syncs) plugs in.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "guidecache/guide_field.h"
#include "master/film.h"
#include "worker/embree_backend.h"
#include "worker/render_tile.h"
#include "worker/scene_data.h"

namespace tessera {

struct RenderOptions {
  uint32_t spp = 16;            // 0 = unlimited (then time_budget_s must be set)
  double time_budget_s = 0.0;   // 0 = none; whole passes are rendered until it is spent
  int32_t max_depth = 5;
  bool nee = true;
  uint64_t seed = 0;
  int32_t threads = 0;          // 0 = all cores
  int32_t tile_size = 16;
  uint32_t max_pass_spp = 8;
  GuideLearnSchedule guide_learn;
  bool guide_roulette = true;   // guide-driven Russian roulette (guided renders)
  bool force_full_specialisation = false;  // benchmark switch: ignore the effects set
  bool progress = true;
};

// What one pass did (learning progress shows here when guiding).
struct PassStats {
  uint32_t spp = 0;           // samples per pixel in this pass
  double seconds = 0.0;       // wall time of the pass, guide fold included
  uint64_t samples = 0;
  uint64_t zero_radiance = 0;
  uint64_t vertices = 0;      // surface interactions
  uint64_t guided_samples = 0;
  uint64_t guidable_vertices = 0;
};

struct RenderStats {
  uint32_t spp = 0;
  uint32_t passes = 0;
  double seconds = 0.0;
  TileCounters counters;
  uint32_t effects = 0;
  uint32_t specialisation = 0;
  int32_t threads = 0;
  std::string stop_reason;
  std::vector<PassStats> pass_stats;
  std::string guide_mode = "none";  // none | qtable | qlearning
  GuideFieldStats guide;            // as the field stood at the end (when guided)
  double guide_fold_seconds = 0.0;
  GuideLearnSchedule guide_learn;  // the learning schedule the render ran with
  bool guide_roulette = false;     // whether guide-driven roulette was on
};

struct RenderResult {
  Film film;
  RenderStats stats;
};

// The integrator specialisation a render with these options runs.
uint32_t effective_specialisation(const SceneData& scene, const RenderOptions& options, bool guiding);

// Renders passes until options.spp or the time budget is reached. With a
// guide, every pass samples from the field as it stood when the pass began
// and the pass's learning is folded in before the next one.
RenderResult render(const SceneData& scene, const EmbreeScene& embree, const RenderOptions& options,
                    GuideField* guide = nullptr);

}  // namespace tessera
