// tessera bench-rays [SCENE]: raw Embree rtcIntersect1 throughput on random
// incoherent rays in a scene, the yardstick for our own rays/s.
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <atomic>
#include <stdexcept>
#include <chrono>
#include <cstdio>
#include <thread>
#include <vector>

#include "app/commands.h"
#include "app/scene_loading.h"
#include "kernels/rng.h"
#include "kernels/sampling.h"
#include "render/embree_backend.h"

namespace tessera {
namespace {

struct BenchArgs {
  std::string scene;
  int64_t rays = 10000000;
  int64_t threads = 0;
};

int run_bench(const BenchArgs& a) {
  SceneData scene(load_scene_or_builtin(a.scene));
  EmbreeScene embree(scene);
  const EmbreeTracer tracer = embree.tracer();
  const Bounds& b = scene.bounds();
  if (scene.num_triangles() == 0) throw std::runtime_error("bench-rays: the scene has no triangles");
  const int threads = a.threads > 0 ? static_cast<int>(a.threads)
                                    : static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  tbb::task_arena arena(threads);
  // Origins uniform in the scene's bounding box, directions uniform on the
  // sphere: as incoherent as secondary rays get. Rays are generated before
  // the clock starts so that only rtcIntersect1 is timed.
  const uint64_t n = static_cast<uint64_t>(a.rays);
  std::vector<Vec3> origins(n), dirs(n);
  tbb::parallel_for(uint64_t(0), n, [&](uint64_t i) {
    Rng rng = Rng::for_sample(7, i, 0);
    origins[i] = b.lo + (b.hi - b.lo) * Vec3(rng.uniform(), rng.uniform(), rng.uniform());
    dirs[i] = sample_uniform_sphere(rng.uniform2());
  });
  const uint64_t chunk = 4096;
  std::atomic<uint64_t> hits{0};
  auto start = std::chrono::steady_clock::now();
  arena.execute([&] {
    tbb::parallel_for(uint64_t(0), (n + chunk - 1) / chunk, [&](uint64_t c) {
      uint64_t local = 0;
      TraceHit h;
      for (uint64_t i = c * chunk; i < std::min(n, (c + 1) * chunk); ++i)
        local += tracer.intersect(origins[i], dirs[i], 3.4e38f, &h);
      hits += local;
    });
  });
  double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::printf("{\"rays\": %llu, \"seconds\": %.6f, \"rays_per_second\": %.3f, \"hit_fraction\": %.4f, \"threads\": %d}\n",
              static_cast<unsigned long long>(n), secs, n / secs, static_cast<double>(hits) / n, threads);
  return 0;
}

}  // namespace

CommandRunner add_bench_rays_command(CLI::App& app) {
  auto a = std::make_shared<BenchArgs>();
  CLI::App* c = app.add_subcommand("bench-rays", "Benchmark raw Embree rtcIntersect1 on random incoherent rays in a scene");
  c->add_option("scene", a->scene, "Scene file (omit for the built-in Cornell box)");
  c->add_option("--rays", a->rays, "Number of rays")->check(CLI::Range(int64_t(1), int64_t(1) << 30));
  c->add_option("--threads", a->threads, "Threads (0 = all cores)")->check(CLI::Range(0, 4096));
  return [a] { return run_bench(*a); };
}

}  // namespace tessera
