#include "master/renderer.h"

#include <tbb/global_control.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <mutex>
#include <thread>
#include <vector>

#include "master/progress.h"

namespace tessera {

uint32_t effective_specialisation(const SceneData& scene, const RenderOptions& options, bool guiding) {
  uint32_t spec = options.force_full_specialisation ? (kSpecAll & ~kSpecGuiding) : specialisation_for(scene.effects());
  return guiding ? spec | kSpecGuiding : spec;
}

RenderResult render(const SceneData& scene, const EmbreeScene& embree, const RenderOptions& opt, GuideField* guide) {
  const SceneView& view = scene.view();
  const int32_t w = view.camera.width, h = view.camera.height;
  RenderResult result;
  result.film = Film(w, h);
  RenderStats& stats = result.stats;
  stats.effects = scene.effects();
  stats.specialisation = effective_specialisation(scene, opt, guide != nullptr);

  std::vector<TileJob> tiles;
  const int32_t ts = std::max(1, opt.tile_size);
  for (int32_t y = 0; y < h; y += ts)
    for (int32_t x = 0; x < w; x += ts) tiles.push_back(TileJob{x, y, std::min(x + ts, w), std::min(y + ts, h), 0, 0});

  const int32_t threads = opt.threads > 0 ? opt.threads : static_cast<int32_t>(std::max(1u, std::thread::hardware_concurrency()));
  stats.threads = threads;
  tbb::task_arena arena(threads);

  TileSettings ts_settings;
  ts_settings.seed = opt.seed;
  ts_settings.path.max_depth = opt.max_depth;
  ts_settings.path.nee = opt.nee;
  ts_settings.specialisation = stats.specialisation;
  ts_settings.learn = stats.guide_learn = opt.guide_learn;
  ts_settings.path.guided_roulette = opt.guide_roulette;
  stats.guide_roulette = guide != nullptr && opt.guide_roulette;
  const EmbreeTracer tracer = embree.tracer();

  const uint64_t pixels = static_cast<uint64_t>(w) * h;
  Progress progress(opt.progress, opt.spp > 0 ? pixels * opt.spp : 0, opt.time_budget_s);
  std::atomic<uint64_t> samples_done{0};
  std::mutex counters_mutex;
  const auto start = std::chrono::steady_clock::now();
  auto elapsed = [&] { return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(); };

  uint32_t spp_done = 0;
  double last_pass_s = 0.0;
  for (uint32_t pass = 0;; ++pass) {
    if (opt.spp > 0 && spp_done >= opt.spp) {
      stats.stop_reason = "spp";
      break;
    }
    if (opt.time_budget_s > 0 && pass > 0 && elapsed() + last_pass_s > opt.time_budget_s) {
      stats.stop_reason = "time";
      break;
    }
    // Pass sizes 1, 1, 2, 4, ... up to max_pass_spp: early passes are quick
    // (a time budget gets fine granularity), later ones amortise overhead.
    uint32_t pass_spp = std::min<uint32_t>(opt.max_pass_spp, pass == 0 ? 1u : (1u << std::min(pass - 1, 20u)));
    if (opt.spp > 0) pass_spp = std::min(pass_spp, opt.spp - spp_done);
    const double pass_start = elapsed();
    const TileCounters before = stats.counters;
    if (guide) ts_settings.path.guide = guide->view();
    arena.execute([&] {
      tbb::parallel_for(size_t(0), tiles.size(), [&](size_t i) {
        TileJob job = tiles[i];
        job.sample_begin = spp_done;
        job.sample_end = spp_done + pass_spp;
        TileCounters tc = render_tile(view, tracer, ts_settings, job, result.film);
        {
          std::lock_guard<std::mutex> lock(counters_mutex);
          stats.counters.add(tc);  // integer sums: order-independent
        }
        uint64_t done = samples_done.fetch_add(tc.samples) + tc.samples;
        progress.advance(done, spp_done);
      });
    });
    if (guide) {
      const double fold_start = elapsed();
      guide->fold();
      stats.guide_fold_seconds += elapsed() - fold_start;
    }
    spp_done += pass_spp;
    ++stats.passes;
    last_pass_s = elapsed() - pass_start;
    PassStats ps;
    ps.spp = pass_spp;
    ps.seconds = last_pass_s;
    ps.samples = stats.counters.samples - before.samples;
    ps.zero_radiance = stats.counters.zero_radiance - before.zero_radiance;
    ps.vertices = stats.counters.path.vertices - before.path.vertices;
    ps.guided_samples = stats.counters.path.guided_samples - before.path.guided_samples;
    ps.guidable_vertices = stats.counters.path.guidable_vertices - before.path.guidable_vertices;
    stats.pass_stats.push_back(ps);
  }
  stats.spp = spp_done;
  stats.seconds = elapsed();
  if (guide) {
    stats.guide = guide->stats();
    stats.guide_mode = guide->config().target == GuideTarget::QLearning ? "qlearning" : "qtable";
  }
  progress.finish(samples_done.load(), spp_done);
  return result;
}

}  // namespace tessera
