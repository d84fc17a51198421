// A farm inside the test process (InProcessTransport, ranks as threads) on a
// small door-ajar: rank 0 runs the master (1 rendering thread), ranks 1..
// run workers, each with its own backend and guide. Hooks let a test stall
// a rank, as SIGSTOP would, and start one late.
#pragma once

#include <gtest/gtest.h>

#include <condition_variable>
#include <exception>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "../render/render_helpers.h"
#include "comm/inproc_transport.h"
#include "guidecache/guide_kinds.h"
#include "master/farm_master.h"
#include "render/backends.h"
#include "render/embree_backend.h"
#include "worker/farm_worker.h"

namespace tessera::testing {

struct FarmScene {
  SceneData scene;
  mutable EmbreeBackend embree;  // local renders (its per-pass state changes while it renders)
  RenderOptions opt;
  explicit FarmScene(SceneDesc d) : scene(std::move(d)), embree(scene) {
    opt.progress = false;
    opt.spp = 12;
    opt.max_depth = scene.desc().max_depth;
    opt.seed = 5;
    opt.threads = 1;
  }
  std::unique_ptr<GuideField> make_guide() const {
    return std::make_unique<GuideField>(GuideConfig{}, scene.bounds().lo, scene.bounds().hi, scene.view().num_lights,
                                        scene.max_emitted_radiance());
  }
  std::unique_ptr<NeuralGuide> make_neural() const {
    NeuralGuideConfig c;
    c.width = 16;
    c.steps_per_pass = 4;
    return std::make_unique<NeuralGuide>(c, scene.bounds().lo, scene.bounds().hi, scene.max_emitted_radiance(),
                                         scene.view().num_lights);
  }
};

inline SceneDesc door_ajar(int32_t width = 48, int32_t height = 36) {
  SceneDesc d = load_pbrt_file(source_dir() + "/scenes/door-ajar.pbrt");
  d.film.xres = width;
  d.film.yres = height;
  return d;
}

inline void expect_same_counters(const TileCounters& a, const TileCounters& b) {
  EXPECT_EQ(a.samples, b.samples);
  EXPECT_EQ(a.zero_radiance, b.zero_radiance);
  EXPECT_EQ(a.path.rays, b.path.rays);
  EXPECT_EQ(a.path.shadow_rays, b.path.shadow_rays);
  EXPECT_EQ(a.path.guide_updates, b.path.guide_updates);
  EXPECT_EQ(a.path.guided_samples, b.path.guided_samples);
}

// A gate a thread waits at until the test opens it.
class Gate {
 public:
  void wait() {
    std::unique_lock<std::mutex> lock(mutex_);
    opened_.wait(lock, [&] { return open_; });
  }
  void open() {
    std::lock_guard<std::mutex> lock(mutex_);
    open_ = true;
    opened_.notify_all();
  }

 private:
  std::mutex mutex_;
  std::condition_variable opened_;
  bool open_ = false;
};

enum class FarmGuide { None, Table, Neural };

struct FarmHooks {
  double lease_s = 30.0;
  double timeout_s = 600.0;
  // Per rank (by index; missing: none): the worker's pause hook, and a gate
  // its thread waits at before it starts (says hello).
  std::vector<std::function<void(const char*)>> worker_pause;
  std::vector<Gate*> start_gate;
  std::function<void(const char*)> master_pause;
  // Called once the master is done (finish() has returned), before the
  // workers are joined: the test opens the gates of stalled workers here.
  std::function<void()> after_finish;
};

struct FarmRun {
  RenderResult result;
  std::vector<std::unique_ptr<Guide>> guides;  // every rank's guide at the end
  std::vector<SilentRank> silent;              // what finish() returned
};

inline std::unique_ptr<Guide> make_farm_guide(const FarmScene& fs, FarmGuide kind) {
  if (kind == FarmGuide::Table) return fs.make_guide();
  if (kind == FarmGuide::Neural) return fs.make_neural();
  return nullptr;
}

// backends[r] renders rank r (Embree where none is named).
inline FarmRun render_farm(const FarmScene& fs, int32_t ranks, FarmGuide guide, bool sync,
                           const std::vector<std::string>& backends = {}, const FarmHooks& hooks = {}) {
  InProcessHub hub(ranks);
  std::vector<std::unique_ptr<Transport>> ends;
  FarmRun run;
  std::vector<std::unique_ptr<TileBackend>> rank_backends;
  for (int32_t r = 0; r < ranks; ++r) {
    ends.push_back(hub.endpoint(r));
    run.guides.push_back(make_farm_guide(fs, guide));
    rank_backends.push_back(make_tile_backend(r < static_cast<int32_t>(backends.size()) ? backends[r] : "embree", fs.scene));
  }
  const uint32_t spec = effective_specialisation(fs.scene, fs.opt, run.guides[0].get());
  std::vector<std::thread> workers;
  for (int32_t r = 1; r < ranks; ++r) {
    workers.emplace_back([&, r] {
      if (r < static_cast<int32_t>(hooks.start_gate.size()) && hooks.start_gate[r]) hooks.start_gate[r]->wait();
      FarmWorkerOptions options;
      options.sync_guide = sync;
      options.timeout_s = hooks.timeout_s;
      options.scene_fingerprint = fs.scene.fingerprint();
      if (r < static_cast<int32_t>(hooks.worker_pause.size())) options.pause = hooks.worker_pause[r];
      run_farm_worker(*ends[r], *rank_backends[r], make_tile_settings(fs.opt, spec, guide != FarmGuide::None),
                      run.guides[r], options);
    });
  }
  FarmMasterOptions options;
  options.sync_guide = sync;
  options.lease_s = hooks.lease_s;
  options.guide = run.guides[0].get();
  options.scene_fingerprint = fs.scene.fingerprint();
  options.pause = hooks.master_pause;
  FarmMaster master(*ends[0], *rank_backends[0], options);
  // A failing render still stops and joins the workers, then fails the test.
  std::exception_ptr failed;
  try {
    run.result = render(fs.scene, master, fs.opt, run.guides[0].get());
  } catch (...) {
    failed = std::current_exception();
  }
  run.silent = master.finish();
  if (hooks.after_finish) hooks.after_finish();
  for (auto& w : workers) w.join();
  if (failed) std::rethrow_exception(failed);
  return run;
}

}  // namespace tessera::testing
