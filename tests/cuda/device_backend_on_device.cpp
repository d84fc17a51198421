// The CUDA backend on a GPU, built without the renderer's libraries (only
// the device backend, the packed scene and the guide field), so that a
// machine with a GPU and nothing else runs it. For each fixture
// (gpu_fixture.h, written by make_gpu_fixtures on a machine with the full
// build):
//   - unguided: the image agrees with the host emulation's (statistically:
//     nvcc contracts multiply-adds), has no NaN/Inf, and a second render is
//     the same bit for bit;
//   - guided (passes of 1, 1, 2, 4, 8... spp, folded between): learning comes
//     back from the device, the image agrees with the unguided one, and a
//     second guided render is the same bit for bit with the same field;
//   - neural guide (the network runs on the device, trains here between
//     passes: 16 passes of 1 spp, then 2, 4, 8...): targets come back and
//     train it, the image agrees with the unguided one, and a second render
//     gives the same image and the same weights bit for bit;
//   - figures: samples/s unguided and guided, time per path vertex guided /
//     unguided (and the network's training share); against Embree on the
//     machine that made the fixture (the 2-core CPU) and against the same
//     kernels on this machine's own cores; relMSE of none, the table and the
//     network at equal time (0.5 s and 2 s, or TESSERA_GPU_EQUAL_TIME) against
//     a 64x longer unguided render of another seed.
// Usage: device_backend_on_device FIXTURE...   (exit 0 pass, 1 fail, 77 no device;
// --probe: 0 when a device is here; TESSERA_GPU_CHECK_DRY_RUN=1: host
// threads stand in for the GPU, to check this program itself)
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <new>
#include <stdexcept>
#include <thread>
#include <vector>

#include "cuda_check.h"
#include "device_pass.h"
#include "gpu_fixture.h"
#include "guidecache/table/guide_field.h"
#include "guidecache/neural/neural_guide.h"
#include "render/guide_binding.h"
#include "render/device_backend.h"
#include "render/host_memory_device.h"

namespace tessera::cuda_check {
namespace {

// The device kernels' bodies on this machine's own cores (std::thread): the
// GPU against the CPU of the same machine, same code, same run.
class HostThreadsDevice : public HostMemoryDevice {
 public:
  explicit HostThreadsDevice(int threads) : threads_(std::max(1, threads)) {}
  std::string backend_name() const override { return "host-threads"; }
  std::string description() const override { return std::to_string(threads_) + " host threads"; }
  bool has_media_kernels() const override { return false; }
  void start(const DeviceLaunch& launch, uint32_t spec) override {
    switch (served_specialisation(spec)) {
      case kServedSurface | kSpecGuiding | kSpecNeural: return run<kServedSurface | kSpecGuiding | kSpecNeural>(launch);
      case kServedSurface | kSpecGuiding: return run<kServedSurface | kSpecGuiding>(launch);
      case kServedSurface: return run<kServedSurface>(launch);
      default: throw std::runtime_error("host threads: no media kernels here");
    }
  }

 private:
  template <uint32_t Spec>
  void run(const DeviceLaunch& launch) {
    const uint64_t steps = uint64_t{launch.num_tiles} * launch.max_samples;
    std::atomic<uint64_t> next{0};
    std::vector<std::thread> pool;
    for (int t = 0; t < threads_; ++t)
      pool.emplace_back([&] {
        for (uint64_t i = next++; i < steps; i = next++)
          for (uint32_t p = 0; p < launch.max_tile_pixels; ++p)
            trace_device_sample<Spec>(launch, static_cast<uint32_t>(i / launch.max_samples), p,
                                      static_cast<uint32_t>(i % launch.max_samples));
      });
    for (std::thread& t : pool) t.join();
    for (uint32_t tile = 0; tile < launch.num_tiles; ++tile) {
      for (uint32_t p = 0; p < launch.max_tile_pixels; ++p) accumulate_device_pixel(launch, tile, p);
      gather_device_targets(launch, tile);
    }
  }
  int threads_;
};

struct Timed {
  Film film;
  TileCounters counters;
  double seconds = 0.0;
};

// Whether a render goes on: below `spp` samples per pixel and, with
// seconds > 0, within that many seconds (checked between passes).
bool goes_on(uint32_t done, uint32_t spp, double seconds, std::chrono::steady_clock::time_point t0) {
  return done < spp && !(seconds > 0.0 && std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count() >= seconds);
}

// Passes of 1, 1, 2, 4, 8, ... spp (at most max_pass) up to `spp` (guided or
// not, the same passes), or for `seconds`; the guide folded after each.
Timed render(DeviceBackend& backend, const GpuFixture& f, GuideField* guide, uint32_t spp, double seconds = 0.0,
             uint32_t max_pass = 8) {
  Timed t{Film(f.width, f.height), {}, 0.0};
  TileSettings s = f.settings;
  if (guide) s.specialisation |= kSpecGuiding;
  const auto t0 = std::chrono::steady_clock::now();
  uint32_t done = 0;
  for (uint32_t pass = 0; goes_on(done, spp, seconds, t0); ++pass) {
    const uint32_t n = std::min(spp - done, pass == 0 ? 1u : std::min(max_pass, 1u << std::min(pass - 1, 20u)));
    if (guide) s.path.guide = guide->view();
    t.counters.add(render_film_pass(backend, s, t.film, done, done + n));
    if (guide) guide->fold();
    done += n;
  }
  t.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return t;
}

// The network: passes of 1 spp while every sample learns (16), then 2, 4,
// 8, 8...; trained here after each (every round as one process runs it).
Timed render_neural(DeviceBackend& backend, const GpuFixture& f, NeuralGuide& guide, uint32_t spp, double seconds = 0.0) {
  Timed t{Film(f.width, f.height), {}, 0.0};
  TileSettings s = f.settings;
  s.specialisation |= kSpecGuiding | kSpecNeural;
  const auto t0 = std::chrono::steady_clock::now();
  uint32_t done = 0;
  for (uint32_t pass = 0; goes_on(done, spp, seconds, t0); ++pass) {
    const uint32_t n = std::min(spp - done, pass < 16 ? 1u : std::min(8u, 2u << std::min(pass - 16, 20u)));
    bind_guide(guide, &s);
    t.counters.add(render_film_pass(backend, s, t.film, done, done + n));
    combine_guide_rounds(guide, [](std::vector<uint64_t>&) {});
    done += n;
  }
  t.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return t;
}

// What the environment asks of the figures (read once, before any render,
// so that a typo costs no device time):
//   TESSERA_GPU_NEURAL="TARGETS,STEPS": the network's targets per tile and
//     Adam steps per pass (as --neural-targets and --neural-steps), for the
//     network's checks as well as its figures;
//   TESSERA_GPU_EQUAL_TIME="0.5,2,6": the equal-time budgets in seconds
//     (default 0.5 and 2; a larger image fills the device and wants longer).
struct FigureSettings {
  NeuralGuideConfig network;
  std::vector<double> budgets{0.5, 2.0};
};

FigureSettings figure_settings() {
  FigureSettings f;
  if (const char* env = std::getenv("TESSERA_GPU_NEURAL")) {
    unsigned long targets = 0, steps = 0;
    const char* p = env;
    if (!read_count(&p, 1ul << 20, &targets) || *p++ != ',' || !read_count(&p, 1024, &steps) || *p != '\0')
      throw std::runtime_error(std::string("TESSERA_GPU_NEURAL: '") + env +
                               "' is not TARGETS,STEPS (targets 1 to 2^20, steps 1 to 1024)");
    f.network.tile_targets = static_cast<uint32_t>(targets);
    f.network.steps_per_pass = static_cast<uint32_t>(steps);
  }
  if (const char* env = std::getenv("TESSERA_GPU_EQUAL_TIME")) {
    f.budgets.clear();
    for (const char* p = env;;) {
      char* end = nullptr;
      const double seconds = std::strtod(p, &end);
      if (end == p || !(seconds > 0.0 && seconds <= 600.0) || (*end != ',' && *end != '\0'))
        throw std::runtime_error(std::string("TESSERA_GPU_EQUAL_TIME: '") + env +
                                 "' is not a list of seconds (each above 0, at most 600, comma-separated)");
      f.budgets.push_back(seconds);
      if (*end == '\0') break;
      p = end + 1;
    }
  }
  return f;
}

// Relative MSE against a reference, as tessera's image metrics define it:
// the mean over pixels and channels of (A - F)^2 / (F^2 + 0.01).
double rel_mse(const Film& a, const Film& reference) {
  double sum = 0.0;
  for (size_t i = 0; i < a.pixels.size(); ++i)
    for (int c = 0; c < 3; ++c) {
      const PixelAccum& p = a.pixels[i];
      const PixelAccum& r = reference.pixels[i];
      const double va = p.n ? p.sum[c] / double(p.n) : 0.0, vr = r.n ? r.sum[c] / double(r.n) : 0.0;
      sum += (va - vr) * (va - vr) / (vr * vr + 1e-2);
    }
  return sum / (3.0 * double(a.pixels.size()));
}

// Equal time on the device: unguided, the table and the network (training
// included) for the same seconds, each against a long unguided reference.
// The reference takes independent samples of a seed of its own (whatever
// the fixture's sampler): were its samples the renders' own, their errors
// would be understated (the unguided render's by the share of the
// reference it makes up).
void equal_time(DeviceBackend& backend, const GpuFixture& f, uint32_t ref_spp, const std::vector<double>& budgets,
                const NeuralGuideConfig& network_config) {
  GpuFixture independent = f;
  independent.settings.seed = f.settings.seed ^ 0x9e3779b97f4a7c15ull;
  independent.settings.sampler = SamplerSetup{};
  independent.settings.sampler.kind = SamplerKind::Independent;
  independent.settings.sampler.seed = independent.settings.seed;
  const Timed ref = render(backend, independent, nullptr, ref_spp, 0.0, 256);
  std::printf("  equal time on the device, against %u spp unguided, independent samples of another seed (%.1f s):\n",
              ref_spp, ref.seconds);
  for (const double seconds : budgets) {
    const Timed u = render(backend, f, nullptr, ~0u, seconds);
    GuideField table(GuideConfig{}, f.lo, f.hi, f.lights, f.max_emitted);
    const Timed g = render(backend, f, &table, ~0u, seconds);
    NeuralGuide network(network_config, f.lo, f.hi, f.max_emitted, f.lights);
    const Timed n = render_neural(backend, f, network, ~0u, seconds);
    const double eu = rel_mse(u.film, ref.film), eg = rel_mse(g.film, ref.film), en = rel_mse(n.film, ref.film);
    std::printf("    %.2f s: relMSE none %.3g (%u spp), qtable %.3g (%u spp, %.2fx none's), neural %.3g (%u spp, %.2fx none's, "
                "%.2fx the table's; training %.0f %% of its time)\n",
                seconds, eu, static_cast<unsigned>(u.film.pixels[0].n), eg, static_cast<unsigned>(g.film.pixels[0].n), eg / eu,
                en, static_cast<unsigned>(n.film.pixels[0].n), en / eu, en / eg,
                100.0 * network.stats().train_seconds / n.seconds);
  }
}

bool identical(const Film& a, const Film& b) {
  return a.pixels.size() == b.pixels.size() &&
         std::memcmp(a.pixels.data(), b.pixels.data(), a.pixels.size() * sizeof(PixelAccum)) == 0;
}

bool finite(const Film& f) {
  for (const PixelAccum& p : f.pixels)
    for (int c = 0; c < 3; ++c)
      if (!std::isfinite(p.sum[c])) return false;
  return true;
}

// Means within 4 standard errors of their difference, per channel.
bool agree(const Film& a, const Film& b, const char* what, const std::string& name) {
  const testing::ChannelStats ma = testing::channel_stats(a), mb = testing::channel_stats(b);
  bool ok = true;
  for (int c = 0; c < 3; ++c) {
    const double tol = 4.0 * std::sqrt(ma.se[c] * ma.se[c] + mb.se[c] * mb.se[c]);
    const bool near = std::fabs(ma.mean[c] - mb.mean[c]) <= tol;
    std::printf("  %s %s channel %d: %.6f vs %.6f (tolerance %.6f)%s\n", name.c_str(), what, c, ma.mean[c], mb.mean[c],
                tol, near ? "" : "  FAIL");
    ok &= near;
  }
  return ok;
}

bool check(const std::string& path, const FigureSettings& settings) {
  GpuFixture f;
  const PackedScene packed = load_fixture(path, &f);
  std::string why;
  // A dry run of this program where there is no GPU: the host threads stand in for it.
  std::unique_ptr<DeviceApi> device =
      std::getenv("TESSERA_GPU_CHECK_DRY_RUN") ? std::make_unique<HostThreadsDevice>(2) : open_cuda_device(&why);
  if (!device) {
    std::printf("FAIL %s: %s\n", path.c_str(), why.c_str());
    return false;
  }
  const std::string description = device->description();
  DeviceBackend backend(packed, std::move(device));
  Film reference(f.width, f.height);
  reference.pixels = f.reference;
  bool ok = true;

  render(backend, f, nullptr, f.spp);  // warm-up: first launches, allocations
  const Timed a = render(backend, f, nullptr, f.spp), b = render(backend, f, nullptr, f.spp);
  const double samples = double(f.width) * f.height * f.spp;
  std::printf("%s on %s: %dx%d, %u spp\n", f.name.c_str(), description.c_str(), f.width, f.height, f.spp);
  if (!identical(a.film, b.film)) std::printf("  FAIL unguided renders differ between runs\n"), ok = false;
  if (!finite(a.film)) std::printf("  FAIL non-finite pixel sums\n"), ok = false;
  ok &= agree(reference, a.film, "unguided vs host emulation", f.name);
  // Host threads in place of the GPU compute the emulation's bits, in passes or not.
  const bool dry_run = std::getenv("TESSERA_GPU_CHECK_DRY_RUN") != nullptr;
  if (dry_run && !identical(reference, a.film))
    std::printf("  FAIL the dry run's image differs from the host emulation's bits\n"), ok = false;

  auto make_guide = [&] { return GuideField(GuideConfig{}, f.lo, f.hi, f.lights, f.max_emitted); };
  GuideField g1 = make_guide(), g2 = make_guide();
  const Timed ga = render(backend, f, &g1, f.spp), gb = render(backend, f, &g2, f.spp);
  if (ga.counters.path.guide_updates == 0 || g1.stats().updates == 0)
    std::printf("  FAIL no learning came back from the device\n"), ok = false;
  if (!identical(ga.film, gb.film) || !(g1 == g2))
    std::printf("  FAIL guided renders or fields differ between runs\n"), ok = false;
  if (!finite(ga.film)) std::printf("  FAIL non-finite guided pixel sums\n"), ok = false;
  ok &= agree(a.film, ga.film, "guided vs unguided", f.name);

  auto make_network = [&] {
    return std::make_unique<NeuralGuide>(settings.network, f.lo, f.hi, f.max_emitted, f.lights);
  };
  auto n1 = make_network(), n2 = make_network();
  const Timed na = render_neural(backend, f, *n1, f.spp), nb = render_neural(backend, f, *n2, f.spp);
  const NeuralGuideStats ns = n1->stats();
  if (ns.steps == 0 || ns.targets == 0) std::printf("  FAIL the network learned nothing from the device\n"), ok = false;
  if (na.counters.path.guided_samples == 0) std::printf("  FAIL the network guided no sample\n"), ok = false;
  if (!identical(na.film, nb.film) || !(*n1 == *n2))
    std::printf("  FAIL neural renders or weights differ between runs\n"), ok = false;
  if (!finite(na.film)) std::printf("  FAIL non-finite neural pixel sums\n"), ok = false;
  ok &= agree(a.film, na.film, "neural vs unguided", f.name);

  const double unguided_rate = samples / a.seconds, guided_rate = samples / ga.seconds;
  const double unguided_vertex = a.seconds / double(a.counters.path.vertices);
  const double guided_vertex = ga.seconds / double(ga.counters.path.vertices);
  std::printf("  unguided: %.2f s, %.2f Msamples/s, %.1f ns per path vertex\n", a.seconds, unguided_rate * 1e-6,
              unguided_vertex * 1e9);
  std::printf("  guided:   %.2f s, %.2f Msamples/s, %.1f ns per path vertex (%.2fx unguided's), %llu guided samples\n",
              ga.seconds, guided_rate * 1e-6, guided_vertex * 1e9, guided_vertex / unguided_vertex,
              static_cast<unsigned long long>(ga.counters.path.guided_samples));
  const double neural_vertex = na.seconds / double(na.counters.path.vertices);
  std::printf("  the network's settings: %u targets per tile, %u steps per pass\n", n1->config().tile_targets,
              n1->config().steps_per_pass);
  std::printf("  neural:   %.2f s, %.2f Msamples/s, %.1f ns per path vertex (%.2fx unguided's, %.2fx the table's), "
              "training %.2f s (%.0f %%), %llu targets, %llu steps, %llu guided samples\n",
              na.seconds, samples / na.seconds * 1e-6, neural_vertex * 1e9, neural_vertex / unguided_vertex,
              neural_vertex / guided_vertex, ns.train_seconds, 100.0 * ns.train_seconds / na.seconds,
              static_cast<unsigned long long>(ns.targets), static_cast<unsigned long long>(ns.steps),
              static_cast<unsigned long long>(na.counters.path.guided_samples));
  std::printf("  where the fixture was made (%d threads): Embree %.3f Msamples/s, the device kernels %.3f Msamples/s; "
              "GPU unguided is %.1fx Embree there\n",
              f.host_threads, samples / f.embree_seconds * 1e-6, samples / f.host_seconds * 1e-6,
              unguided_rate / (samples / f.embree_seconds));
  // The same kernels on this machine's cores.
  const int cores = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  DeviceBackend host(packed, std::make_unique<HostThreadsDevice>(cores));
  const Timed h = render(host, f, nullptr, f.spp);
  GuideField gh = make_guide();
  const Timed hg = render(host, f, &gh, f.spp);
  auto nh = make_network();
  const Timed hn = render_neural(host, f, *nh, f.spp);
  std::printf("  this machine's %d cores, the same kernels: %.3f Msamples/s unguided, %.3f guided, %.3f neural; "
              "GPU is %.1fx, %.1fx, %.1fx\n",
              cores, samples / h.seconds * 1e-6, samples / hg.seconds * 1e-6, samples / hn.seconds * 1e-6,
              h.seconds / a.seconds, hg.seconds / ga.seconds, hn.seconds / na.seconds);
  ok &= agree(a.film, h.film, "GPU vs this machine's cores", f.name);
  ok &= agree(na.film, hn.film, "neural: GPU vs this machine's cores", f.name);
  if (dry_run && !identical(a.film, h.film)) std::printf("  FAIL the dry run's two host renders differ\n"), ok = false;
  if (dry_run && (!identical(na.film, hn.film) || !(*n1 == *nh)))
    std::printf("  FAIL the dry run's two host neural renders differ\n"), ok = false;
  // Figures only (the dry run: briefly, to run the code).
  if (dry_run)
    equal_time(backend, f, 4 * f.spp, {0.05, 0.1}, settings.network);
  else
    equal_time(backend, f, 64 * f.spp, settings.budgets, settings.network);
  return ok;
}

}  // namespace
}  // namespace tessera::cuda_check

int main(int argc, char** argv) {
  if (!std::getenv("TESSERA_GPU_CHECK_DRY_RUN") && !tessera::cuda_check::device_present()) return 77;
  if (argc == 2 && std::strcmp(argv[1], "--probe") == 0) return 0;  // a device is here
  if (argc < 2) {
    std::printf("usage: device_backend_on_device FIXTURE...\n");
    return 2;
  }
  tessera::cuda_check::FigureSettings settings;
  try {
    settings = tessera::cuda_check::figure_settings();
  } catch (const std::exception& e) {
    std::printf("device_backend_on_device: %s\n", e.what());
    return 2;
  }
  bool ok = true;
  for (int i = 1; i < argc; ++i) {
    try {
      ok &= tessera::cuda_check::check(argv[i], settings);
    } catch (const std::exception& e) {
      std::printf("FAIL %s: %s\n", argv[i], e.what());
      ok = false;
    }
  }
  std::printf("%s\n", ok ? "device backend: all checks passed" : "device backend: FAILED");
  return ok ? 0 : 1;
}
