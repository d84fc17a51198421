#include "render/renderer.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <thread>
#include <vector>

#include "render/error_estimate.h"
#include "render/interrupt.h"
#include "render/ordered_splats.h"
#include "render/progress.h"
#include "render/cpu_affinity.h"
#include "render/guide_binding.h"

namespace tessera {

uint32_t effective_specialisation(const SceneData& scene, const RenderOptions& options, const Guide* guide) {
  uint32_t spec = specialisation_for(scene.effects());
  if (options.force_full_specialisation) spec = (kSpecSurfaceAll & ~kSpecGuiding) | (spec & kSpecMedia);
  if (!guide) return spec;
  // The network runs the full surface integrator, or in scenes of Lambertian
  // surfaces and area lights alone one of its own (instantiated_spec): the log and stats say which.
  if ((guide->spec_bits() & kSpecNeural) && !lambertian_area_lights_only(spec))
    spec = kSpecSurfaceAll | (spec & kSpecMedia);
  return spec | guide->spec_bits();
}

TileSettings make_tile_settings(const RenderOptions& opt, uint32_t specialisation, bool guiding) {
  TileSettings ts;
  ts.seed = opt.seed;
  ts.sampler = opt.sampler;
  ts.sampler.seed = opt.seed;
  ts.path.max_depth = opt.max_depth;
  ts.path.nee = opt.nee;
  ts.specialisation = specialisation;
  ts.learn = opt.guide_learn;
  ts.path.guided_roulette = guiding && opt.guide_roulette;
  ts.path.guided_roulette_window = opt.guide_roulette_window;
  ts.path.max_guide_ratio = opt.guide_max_ratio;
  ts.path.light_traced_caustics = opt.light_paths;
  return ts;
}

int32_t render_threads(const RenderOptions& opt, int32_t ranks_on_this_machine) {
  if (opt.threads > 0) return opt.threads;
  const int32_t machine = static_cast<int32_t>(std::max(1u, std::thread::hardware_concurrency()));
  // A rank bound to some cores (mpirun's default) uses those.
  return std::max(1, std::min(usable_cores(), machine / std::max(1, ranks_on_this_machine)));
}

uint32_t pass_spp_for(uint32_t pass, uint32_t max_pass_spp, uint32_t single_passes) {
  if (pass < single_passes) return 1;
  if (single_passes > 0) pass = pass - single_passes + 2;  // then 2, 4, ...
  return std::min<uint32_t>(max_pass_spp, pass == 0 ? 1u : (1u << std::min(pass - 1, 20u)));
}

uint32_t pass_spp_within_budget(uint32_t planned, double left_s, const PassStats& last) {
  if (!(left_s > 0.0)) return 0;
  if (last.spp == 0 || !(last.seconds > 0.0)) return planned;  // nothing measured to go by
  const double learning = std::clamp(last.guide_seconds, 0.0, last.seconds);
  const double per_spp = (last.seconds - learning) / static_cast<double>(last.spp);
  if (learning + per_spp * static_cast<double>(planned) <= left_s) return planned;
  if (!(per_spp > 0.0)) return 0;  // the learning alone does not fit
  const double fit = std::floor((left_s - learning) / per_spp);
  return fit >= 1.0 ? static_cast<uint32_t>(std::min(fit, static_cast<double>(planned))) : 0u;
}

namespace {

// A local pass's tiles: in order, into the image's film.
class FilmQueue : public TileQueue {
 public:
  FilmQueue(const TileSettings& settings, const std::vector<TileJob>& jobs, Film& film,
            const std::function<void(uint64_t)>& on_tile_done)
      : settings_(settings), jobs_(jobs), film_(film), on_tile_done_(on_tile_done), splats_(film, jobs.size()) {}
  bool take(TileTask* task) override {
    // In order, so that light-path splats wait for few earlier tiles (OrderedSplats).
    const size_t i = next_.fetch_add(1);
    if (i >= jobs_.size()) return false;
    *task = TileTask{jobs_[i], film_tile(film_, jobs_[i]), i};
    return true;
  }
  void done(const TileTask& task, uint64_t samples, std::vector<Splat>&& splats) override {
    if (settings_.path.light_traced_caustics)
      splats_.add(task.slot, std::move(splats), job_light_paths(settings_, task.job));
    if (on_tile_done_) on_tile_done_(samples);
  }
  void finish() {
    if (settings_.path.light_traced_caustics) splats_.finish();
  }

 private:
  const TileSettings& settings_;
  const std::vector<TileJob>& jobs_;
  Film& film_;
  const std::function<void(uint64_t)>& on_tile_done_;
  OrderedSplats splats_;
  std::atomic<size_t> next_{0};
};

// Records a pass rendered while --guide auto's trial is pending; keeps the
// unguided passes' sums apart, and takes the loser's samples out of the
// film where the final decision says so (render/guide_trial.h).
void record_trial_pass(RenderResult& result, bool trial_pass, bool guided, const std::vector<PixelAccum>& before,
                       uint32_t pass_spp, const TileCounters& counters_before) {
  std::vector<PixelAccum>& pixels = result.film.pixels;
  std::vector<PixelAccum>& unguided = result.trial_unguided;
  if (!guided) {
    if (unguided.size() != pixels.size()) unguided.assign(pixels.size(), PixelAccum{});
    for (size_t i = 0; i < pixels.size(); ++i) {
      for (int c = 0; c < 3; ++c) {
        unguided[i].sum[c] += pixels[i].sum[c] - before[i].sum[c];
        unguided[i].sum_sq[c] += pixels[i].sum_sq[c] - before[i].sum_sq[c];
      }
      unguided[i].n += pixels[i].n - before[i].n;
    }
  }
  const TileCounters& now = result.stats.counters;
  GuideTrial& t = result.stats.guide_trial;
  const int drop = guide_trial_record(t, trial_pass, guided, result.film, before, pass_spp,
                                      now.samples - counters_before.samples,
                                      now.path.rays + now.path.shadow_rays - counters_before.path.rays -
                                          counters_before.path.shadow_rays);
  if (drop == 1) {
    pixels = unguided;  // the unguided passes alone, exactly
  } else if (drop == 0 && unguided.size() == pixels.size()) {
    for (size_t i = 0; i < pixels.size(); ++i) {
      for (int c = 0; c < 3; ++c) {
        pixels[i].sum[c] -= unguided[i].sum[c];
        pixels[i].sum_sq[c] = std::max(0.0, pixels[i].sum_sq[c] - unguided[i].sum_sq[c]);
      }
      pixels[i].n -= unguided[i].n;
    }
  }
  if (t.state != GuideTrialState::Pending) std::vector<PixelAccum>().swap(unguided);
}

}  // namespace

LocalPassExecutor::LocalPassExecutor(TileBackend& backend, int32_t threads)
    : backend_(backend), threads_(std::max(1, threads)) {}

void LocalPassExecutor::render_pass(const TileSettings& settings, const std::vector<TileJob>& jobs, Film& film,
                                    TileCounters* counters, const std::function<void(uint64_t)>& on_tile_done) {
  FilmQueue queue(settings, jobs, film, on_tile_done);
  backend_.begin_pass(settings);
  counters->add(backend_.render_tiles(queue, threads_));
  queue.finish();
  backend_.end_pass();
}

RenderResult render(const SceneData& scene, TileBackend& backend, const RenderOptions& opt, Guide* guide,
                    const RenderResult* resume, const PassEndHook& on_pass_end) {
  LocalPassExecutor local(backend, render_threads(opt));
  return render(scene, local, opt, guide, resume, on_pass_end);
}

RenderResult render(const SceneData& scene, PassExecutor& executor_ref, const RenderOptions& opt, Guide* guide,
                    const RenderResult* resume, const PassEndHook& on_pass_end) {
  PassExecutor* executor = &executor_ref;
  const SceneView& view = scene.view();
  const int32_t w = view.camera.film_width, h = view.camera.film_height;
  RenderResult result;
  if (resume) {
    result = *resume;
    result.stats.resumed_at_spp = resume->stats.spp;
  } else {
    result.film = Film(w, h);
  }
  RenderStats& stats = result.stats;
  stats.effects = scene.effects();
  stats.spectral = scene.desc().spectral;
  stats.specialisation = effective_specialisation(scene, opt, guide);

  stats.backend = executor->backends();
  stats.threads = executor->total_threads();
  stats.ranks = executor->ranks();
  stats.machines = executor->machines();

  std::vector<TileJob> tiles;
  const int32_t ts = std::max(1, opt.tile_size);
  for (int32_t y = 0; y < h; y += ts)
    for (int32_t x = 0; x < w; x += ts)
      tiles.push_back(TileJob{x, y, std::min(x + ts, w), std::min(y + ts, h), 0, 0, static_cast<uint32_t>(tiles.size())});

  TileSettings settings = make_tile_settings(opt, stats.specialisation, guide != nullptr);
  stats.guide_learn = opt.guide_learn;
  stats.guide_roulette = guide != nullptr && opt.guide_roulette;
  stats.guide_roulette_window = opt.guide_roulette_window;
  stats.guide_max_ratio = opt.guide_max_ratio;

  const uint64_t pixels = static_cast<uint64_t>(w) * h;
  Progress progress(opt.progress, opt.spp > 0 ? pixels * opt.spp : 0, opt.time_budget_s);
  const double seconds_before = stats.seconds;  // a resumed render's time so far counts against --time
  std::atomic<uint64_t> samples_done{stats.counters.samples};
  const auto start = std::chrono::steady_clock::now();
  auto elapsed = [&] {
    return seconds_before + std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  };

  stats.target_error = opt.target_error;
  if (guide) stats.guide_mode = guide->mode();
  if (guide && opt.guide_trial && stats.guide_trial.state == GuideTrialState::Off)
    guide_trial_start(stats.guide_trial, static_cast<uint64_t>(w) * h);
  if (!stats.pass_stats.empty()) progress.set_error(stats.estimated_rel_mse, opt.target_error);

  // A guide that converges per pass learns in passes of one sample (each
  // pass one bootstrap step) while every sample learns.
  // At most 64 of them: a render told to learn from every sample for
  // longer goes on in larger passes (fewer reductions, and trial passes of
  // --guide auto need two samples per pixel).
  const uint32_t single_passes =
      guide && guide->single_sample_learning_passes() ? std::min(opt.guide_learn.all_spp, 64u) : 0u;
  uint32_t spp_done = stats.spp;
  for (uint32_t pass = stats.passes;; ++pass) {
    if (interrupt_requested()) {
      stats.stop_reason = "interrupted";
      break;
    }
    if (opt.spp > 0 && spp_done >= opt.spp) {
      stats.stop_reason = "spp";
      break;
    }
    if (opt.target_error > 0 && stats.estimated_rel_mse >= 0 && stats.estimated_rel_mse <= opt.target_error) {
      stats.stop_reason = "target-error";
      break;
    }
    uint32_t pass_spp = pass_spp_for(pass, opt.max_pass_spp, single_passes);
    if (opt.spp > 0) pass_spp = std::min(pass_spp, opt.spp - spp_done);
    // Sample indices go on past the samples a trial took out of the image.
    const uint32_t sample_index = spp_done + stats.guide_trial.dropped_spp;
    const TrialPass trial_pass = guide_trial_next_pass(stats.guide_trial, sample_index);
    if (opt.time_budget_s > 0 && pass > 0) {
      const double left = opt.time_budget_s - elapsed();
      const uint32_t planned = pass_spp;
      // No pass measured yet (a resume without pass stats): the schedule's, while time is left.
      pass_spp = pass_spp_within_budget(pass_spp, left, stats.pass_stats.empty() ? PassStats{} : stats.pass_stats.back());
      // A trial pass measures its error per sample from each pixel's own
      // samples: cut below two it would measure nothing.
      if (trial_pass != TrialPass::None && pass_spp < planned && pass_spp < 2) pass_spp = 0;
      if (pass_spp == 0) {
        stats.stop_reason = "time";
        break;
      }
    }
    const double pass_start = elapsed();
    const TileCounters before = stats.counters;
    double pass_loss = -1.0, pass_guide_seconds = 0.0;
    // A trial pass's method, else what the trial has (tentatively) decided.
    const bool guided = guide && (trial_pass == TrialPass::Guided ||
                                  (trial_pass == TrialPass::None && guide_trial_guiding(stats.guide_trial)));
    const bool trial_pending = stats.guide_trial.state == GuideTrialState::Pending;
    TileSettings pass_settings = settings;
    if (guided) {
      bind_guide(*guide, &pass_settings);
    } else {
      pass_settings.specialisation &= ~(kSpecGuiding | kSpecNeural);
      pass_settings.path.guided_roulette = false;
    }
    std::vector<PixelAccum> film_before;
    if (trial_pending && (trial_pass != TrialPass::None || !guided)) film_before = result.film.pixels;
    std::vector<TileJob> jobs = tiles;
    for (TileJob& job : jobs) {
      job.sample_begin = sample_index;
      job.sample_end = sample_index + pass_spp;
    }
    executor->render_pass(pass_settings, jobs, result.film, &stats.counters, [&](uint64_t samples) {
      progress.advance(samples_done.fetch_add(samples) + samples, spp_done);
    });
    if (trial_pending) record_trial_pass(result, trial_pass != TrialPass::None, guided, film_before, pass_spp, before);
    if (guided) {
      const double fold_start = elapsed();
      const size_t losses = stats.neural_guide.pass_loss.size();
      combine_guide_rounds(*guide, [&](std::vector<uint64_t>& acc) { executor->reduce_guide(acc); });
      pass_guide_seconds = elapsed() - fold_start;
      stats.guide_fold_seconds += pass_guide_seconds;
      GuideStats guide_stats;
      guide->fill_stats(&guide_stats);
      stats.neural_guide = std::move(guide_stats.neural);
      if (stats.neural_guide.pass_loss.size() > losses) pass_loss = stats.neural_guide.pass_loss.back();
    }
    // A final trial decision may have taken samples out of the image.
    spp_done = sample_index + pass_spp - stats.guide_trial.dropped_spp;
    ++stats.passes;
    const double last_pass_s = elapsed() - pass_start;
    PassStats ps;
    ps.spp = pass_spp;
    ps.seconds = last_pass_s;
    ps.samples = stats.counters.samples - before.samples;
    ps.zero_radiance = stats.counters.zero_radiance - before.zero_radiance;
    ps.vertices = stats.counters.path.vertices - before.path.vertices;
    ps.neural_sites_reused = stats.counters.path.neural_sites_reused - before.path.neural_sites_reused;
    ps.guided_samples = stats.counters.path.guided_samples - before.path.guided_samples;
    ps.guidable_vertices = stats.counters.path.guidable_vertices - before.path.guidable_vertices;
    ps.guide_loss = pass_loss;
    ps.guide_seconds = pass_guide_seconds;
    const ErrorEstimate err = estimate_rel_mse(result.film);
    ps.estimated_rel_mse = err.valid ? err.rel_mse : -1.0;
    stats.estimated_rel_mse = ps.estimated_rel_mse;
    progress.set_error(stats.estimated_rel_mse, opt.target_error);
    stats.pass_stats.push_back(ps);
    stats.spp = spp_done;
    stats.seconds = elapsed();
    if (on_pass_end) {
      const double hook_start = elapsed();
      on_pass_end(result, guide);
      stats.pass_end_seconds += elapsed() - hook_start;
    }
  }
  stats.spp = spp_done;
  stats.seconds = elapsed();
  if (guide) {
    GuideStats guide_stats;
    guide->fill_stats(&guide_stats);
    stats.guide = guide_stats.table;
    stats.neural_guide = std::move(guide_stats.neural);
  }
  progress.finish(samples_done.load(), spp_done);
  return result;
}

}  // namespace tessera
