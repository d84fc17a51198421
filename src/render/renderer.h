// The render loop: passes of samples per pixel over all tiles. A pass's
// tiles are rendered by a PassExecutor: this process's threads (oneTBB), or
// the farm (master/farm_master.h), which hands tiles to ranks. Between
// passes the guide's learning is combined and folded in.
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "guidecache/table/guide_field.h"
#include "guidecache/neural/neural_guide.h"
#include "render/film.h"
#include "render/guide_trial.h"
#include "render/render_tile.h"
#include "render/tile_backend.h"
#include "render/scene_data.h"

namespace tessera {

struct RenderOptions {
  uint32_t spp = 16;            // 0 = unlimited (then time_budget_s must be set)
  double time_budget_s = 0.0;   // 0 = none; passes are rendered until it is spent (pass_spp_within_budget)
  double target_error = 0.0;    // 0 = none; stop after the first pass whose estimated relMSE is <= this
  int32_t max_depth = 5;
  bool nee = true;
  uint64_t seed = 0;
  SamplerSetup sampler;         // kind and parameters (its seed is `seed`)
  int32_t threads = 0;          // 0 = all cores
  int32_t tile_size = 16;
  uint32_t max_pass_spp = 8;
  GuideLearnSchedule guide_learn;
  bool guide_roulette = true;   // guide-driven Russian roulette (guided renders)
  float guide_roulette_window = kGuidedRouletteWindow;  // its window (PathSettings::guided_roulette_window)
  float guide_max_ratio = kMaxGuideRatio;  // PathSettings::max_guide_ratio
  bool force_full_specialisation = false;  // benchmark switch: ignore the effects set
  // --guide auto: guided and unguided passes are compared once the guide has
  // learned, and the render goes on with the cheaper (render/guide_trial.h).
  bool guide_trial = false;
  bool progress = true;
  // Caustics of small lights seen through specular surfaces traced from the
  // lights (integrator/light_paths.h); scene/light_paths.h decides when.
  bool light_paths = false;
};

// What one pass did (learning progress shows here when guiding).
struct PassStats {
  uint32_t spp = 0;           // samples per pixel in this pass
  double seconds = 0.0;       // wall time of the pass, guide fold included
  uint64_t samples = 0;
  uint64_t zero_radiance = 0;
  uint64_t vertices = 0;      // surface interactions
  uint64_t neural_sites_reused = 0;  // of them, those that reused their pixel's first network site
  uint64_t guided_samples = 0;
  uint64_t guidable_vertices = 0;
  double estimated_rel_mse = -1.0;  // of the image after this pass; < 0 = not yet estimable
  double guide_loss = -1.0;   // neural guide: mean training loss after this pass (< 0: none)
  double guide_seconds = 0.0; // the guide's learning after this pass (reductions, fold or training), of `seconds`
};

struct RenderStats {
  std::string backend = "embree";  // what rendered the tiles (embree, bvh, cuda; a farm's distinct ones joined by "+")
  uint32_t spp = 0;
  uint32_t passes = 0;
  double seconds = 0.0;
  TileCounters counters;
  uint32_t effects = 0;
  uint32_t specialisation = 0;
  bool spectral = false;            // spectral transport (else RGB)
  int32_t threads = 0;              // all ranks together
  int32_t ranks = 1;                // processes that rendered (farm)
  int32_t machines = 1;             // the machines (hosts) they ran on
  uint32_t resumed_at_spp = 0;      // > 0: continued from a checkpoint at this many spp
  std::string stop_reason;         // spp | time | target-error | interrupted (SIGINT/SIGTERM)
  double target_error = 0.0;       // the --target-error asked for (0 = none)
  double estimated_rel_mse = -1.0; // of the final image, from its per-pixel variances (< 0 = too few samples)
  double pass_end_seconds = 0.0;   // of `seconds`, spent in the pass-end hook (checkpoints, snapshots)
  std::vector<PassStats> pass_stats;
  std::string guide_mode = "none";  // none | qtable | qlearning | neural
  GuideFieldStats guide;            // as the guide stood at the end (when guided; the network fills bytes, updates, rejections)
  NeuralGuideStats neural_guide;    // the network's own (--guide neural)
  double guide_fold_seconds = 0.0;  // all passes' PassStats::guide_seconds
  double guide_sync_seconds = 0.0;  // farm: time summing the guide's learning over the ranks (rank 0's view)
  uint64_t guide_sync_bytes = 0;    // farm: bytes of the largest round summed
  uint32_t guide_syncs = 0;
  std::string guide_sync = "pass";  // pass | off (each rank learns alone)
  GuideLearnSchedule guide_learn;  // the learning schedule the render ran with
  bool guide_roulette = false;     // whether guide-driven roulette was on
  float guide_roulette_window = 0.f;  // and its window
  float guide_max_ratio = 0.f;        // PathSettings::max_guide_ratio
  GuideTrial guide_trial;          // --guide auto's comparison of guided and unguided passes
};

struct RenderResult {
  Film film;
  RenderStats stats;
  // While --guide auto's trial is pending: the film's unguided passes alone
  // (the rest are guided), so that the final decision can take either out
  // of the image (render/guide_trial.h). Empty otherwise.
  std::vector<PixelAccum> trial_unguided;
};

// The integrator specialisation a render with these options runs.
uint32_t effective_specialisation(const SceneData& scene, const RenderOptions& options, const Guide* guide);

// What every tile of a render is rendered with (the same on every rank).
TileSettings make_tile_settings(const RenderOptions& options, uint32_t specialisation, bool guiding);

// Threads a process renders with: options.threads, or (0) its share of the
// machine's cores when several ranks of a farm run on one machine.
int32_t render_threads(const RenderOptions& options, int32_t ranks_on_this_machine = 1);

// Pass size schedule: 1, 1, 2, 4, ... up to max_pass_spp samples per pixel.
// Early passes are quick (a time budget gets fine granularity, the guide
// learns early), later ones amortise the per-pass overhead. With
// single_passes > 0 the first single_passes passes are 1 spp each and the
// doubling then goes on from 2 (Guide::single_sample_learning_passes: the
// passes in which every sample learns, up to 64). Depends on the pass index and the
// options only, so a resumed render continues the same schedule.
uint32_t pass_spp_for(uint32_t pass, uint32_t max_pass_spp, uint32_t single_passes = 0);

// Samples per pixel of the next pass under a time budget with left_s
// seconds left: the schedule's `planned` where it is expected to fit,
// else as many as are (at the last pass's rendering time per sample per
// pixel, plus its learning between passes), else 0: stop. A --time render
// then ends close to its budget, not up to a whole pass short of it.
uint32_t pass_spp_within_budget(uint32_t planned, double left_s, const PassStats& last);

// Renders one pass of tiles and combines the guide's learning.
class PassExecutor {
 public:
  virtual ~PassExecutor() = default;
  // Renders every job (pixels and sample range) into film, adds the tiles'
  // counters to *counters and calls on_tile_done(samples) after each tile
  // (from any thread).
  virtual void render_pass(const TileSettings& settings, const std::vector<TileJob>& jobs, Film& film,
                           TileCounters* counters, const std::function<void(uint64_t)>& on_tile_done) = 0;
  // Before a fold: makes the pass's guide accumulators the sum over
  // everything that rendered it (a farm sums the ranks'; locally they are).
  virtual void reduce_guide(std::vector<uint64_t>& accumulators) {}
  // How many processes render (1 locally).
  virtual int32_t ranks() const { return 1; }
  // The backends that render (a farm's ranks may differ).
  virtual std::string backends() const = 0;
  virtual int32_t machines() const { return 1; }
  virtual int32_t total_threads() const = 0;
};

// This process's backend: tiles handed out in order, as its threads ask.
class LocalPassExecutor : public PassExecutor {
 public:
  // `backend` outlives the executor; threads: the host threads it renders with.
  LocalPassExecutor(TileBackend& backend, int32_t threads);
  void render_pass(const TileSettings& settings, const std::vector<TileJob>& jobs, Film& film, TileCounters* counters,
                   const std::function<void(uint64_t)>& on_tile_done) override;
  int32_t total_threads() const override { return threads_; }
  std::string backends() const override { return backend_.name(); }

 private:
  TileBackend& backend_;
  int32_t threads_;
};

// Called after every pass (guide folded): where checkpoints are written.
using PassEndHook = std::function<void(const RenderResult& so_far, const Guide* guide)>;

// Renders passes until options.spp, the time budget or the target error is
// reached, whichever comes first. With a guide, every pass samples from the
// field as it stood when the pass began and the pass's learning is folded
// in before the next one. `resume` continues a render from a checkpoint
// (its film, passes and counters; the guide is the caller's).
RenderResult render(const SceneData& scene, PassExecutor& executor, const RenderOptions& options,
                    Guide* guide = nullptr, const RenderResult* resume = nullptr,
                    const PassEndHook& on_pass_end = {});
// The same on this process's backend, with render_threads(options) threads.
RenderResult render(const SceneData& scene, TileBackend& backend, const RenderOptions& options,
                    Guide* guide = nullptr, const RenderResult* resume = nullptr,
                    const PassEndHook& on_pass_end = {});

}  // namespace tessera
