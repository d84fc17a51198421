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
//   - figures: samples/s unguided and guided, time per path vertex guided /
//     unguided, and against the host emulation's figure in the fixture.
// Usage: device_backend_on_device FIXTURE...   (exit 0 pass, 1 fail, 77 no device;
// --probe: 0 when a device is here)
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>

#include "cuda_check.h"
#include "device_pass.h"
#include "gpu_fixture.h"
#include "guidecache/guide_field.h"
#include "worker/device_backend.h"

namespace tessera::cuda_check {
namespace {

struct Timed {
  Film film;
  TileCounters counters;
  double seconds = 0.0;
};

// Passes of 1, 1, 2, 4, 8, ... spp up to `spp`, the guide folded after each.
Timed render(DeviceBackend& backend, const GpuFixture& f, GuideField* guide) {
  Timed t{Film(f.width, f.height), {}, 0.0};
  TileSettings s = f.settings;
  if (guide) s.specialisation |= kSpecGuiding;
  const auto t0 = std::chrono::steady_clock::now();
  uint32_t done = 0;
  for (uint32_t pass = 0; done < f.spp; ++pass) {
    const uint32_t n = std::min(f.spp - done, guide ? (pass == 0 ? 1u : std::min(8u, 1u << (pass - 1))) : f.spp);
    if (guide) s.path.guide = guide->view();
    t.counters.add(render_film_pass(backend, s, t.film, done, done + n));
    if (guide) guide->fold();
    done += n;
  }
  t.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return t;
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
  const FilmMean ma = film_mean_of(a), mb = film_mean_of(b);
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

bool check(const std::string& path) {
  GpuFixture f;
  const PackedScene packed = load_fixture(path, &f);
  std::string why;
  std::unique_ptr<DeviceApi> device = open_cuda_device(&why);
  if (!device) {
    std::printf("FAIL %s: %s\n", path.c_str(), why.c_str());
    return false;
  }
  const std::string description = device->description();
  DeviceBackend backend(packed, std::move(device));
  Film reference(f.width, f.height);
  reference.pixels = f.reference;
  bool ok = true;

  render(backend, f, nullptr);  // warm-up: first launches, allocations
  const Timed a = render(backend, f, nullptr), b = render(backend, f, nullptr);
  const double samples = double(f.width) * f.height * f.spp;
  std::printf("%s on %s: %dx%d, %u spp\n", f.name.c_str(), description.c_str(), f.width, f.height, f.spp);
  if (!identical(a.film, b.film)) std::printf("  FAIL unguided renders differ between runs\n"), ok = false;
  if (!finite(a.film)) std::printf("  FAIL non-finite pixel sums\n"), ok = false;
  ok &= agree(reference, a.film, "unguided vs host emulation", f.name);

  auto make_guide = [&] { return GuideField(GuideConfig{}, f.lo, f.hi, f.lights, f.max_emitted); };
  GuideField g1 = make_guide(), g2 = make_guide();
  const Timed ga = render(backend, f, &g1), gb = render(backend, f, &g2);
  if (ga.counters.path.guide_updates == 0 || g1.stats().updates == 0)
    std::printf("  FAIL no learning came back from the device\n"), ok = false;
  if (!identical(ga.film, gb.film) || !(g1 == g2))
    std::printf("  FAIL guided renders or fields differ between runs\n"), ok = false;
  if (!finite(ga.film)) std::printf("  FAIL non-finite guided pixel sums\n"), ok = false;
  ok &= agree(a.film, ga.film, "guided vs unguided", f.name);

  const double unguided_rate = samples / a.seconds, guided_rate = samples / ga.seconds;
  const double unguided_vertex = a.seconds / double(a.counters.path.vertices);
  const double guided_vertex = ga.seconds / double(ga.counters.path.vertices);
  std::printf("  unguided: %.2f s, %.2f Msamples/s, %.1f ns per path vertex\n", a.seconds, unguided_rate * 1e-6,
              unguided_vertex * 1e9);
  std::printf("  guided:   %.2f s, %.2f Msamples/s, %.1f ns per path vertex (%.2fx unguided's), %llu guided samples\n",
              ga.seconds, guided_rate * 1e-6, guided_vertex * 1e9, guided_vertex / unguided_vertex,
              static_cast<unsigned long long>(ga.counters.path.guided_samples));
  std::printf("  host emulation where the fixture was made (%d threads): %.3f Msamples/s; GPU unguided is %.1fx that\n",
              f.host_threads, samples / f.host_seconds * 1e-6, unguided_rate / (samples / f.host_seconds));
  return ok;
}

}  // namespace
}  // namespace tessera::cuda_check

int main(int argc, char** argv) {
  if (!tessera::cuda_check::device_present()) return 77;
  if (argc == 2 && std::strcmp(argv[1], "--probe") == 0) return 0;  // a device is here
  if (argc < 2) {
    std::printf("usage: device_backend_on_device FIXTURE...\n");
    return 2;
  }
  bool ok = true;
  for (int i = 1; i < argc; ++i) {
    try {
      ok &= tessera::cuda_check::check(argv[i]);
    } catch (const std::exception& e) {
      std::printf("FAIL %s: %s\n", argv[i], e.what());
      ok = false;
    }
  }
  std::printf("%s\n", ok ? "device backend: all checks passed" : "device backend: FAILED");
  return ok ? 0 : 1;
}
