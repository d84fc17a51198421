// One neural-guide inference timed alone (scripts/bench_inference.sh): the
// shipped entry point (neural_infer_cpu: AVX2 where the processor has it) in
// a hot loop over random points, with random weights at the default sizes.
// Usage: bench_inference [axis|random] [lights]. Axis-aligned normals show
// the blocks skipped below the surface; random normals the average case.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <random>
#include <vector>

#include "guidecache/neural/neural_guide.h"

using namespace tessera;

int main(int argc, char** argv) {
  const bool axis = argc < 2 || std::strcmp(argv[1], "random") != 0;
  const uint32_t lights = argc > 2 ? static_cast<uint32_t>(std::atoi(argv[2])) : 0u;
  if (lights != 0 && (lights < kNeuralMinLights || lights > kNeuralMaxLights)) {
    std::fprintf(stderr, "bench_inference: lights must be 0 or %u..%u\n", kNeuralMinLights, kNeuralMaxLights);
    return 2;
  }
  // The shipped guide's view (its bin directions and layouts, default
  // sizes), with random weights and marked trained.
  NeuralGuide guide(NeuralGuideConfig{}, Vec3(0.f), Vec3(1.f), 1.f, lights);
  std::mt19937 rng(1);
  std::uniform_real_distribution<float> w(-0.3f, 0.3f), u(0.f, 1.f);
  for (float& x : guide.mutable_params()) x = w(rng);
  NeuralGuideView v = guide.view();
  v.trained = true;
  constexpr int kPoints = 4096;
  std::vector<Vec3> ps(kPoints), ns(kPoints);
  const Vec3 axes[6] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
  for (int i = 0; i < kPoints; ++i) {
    ps[i] = Vec3(u(rng), u(rng), u(rng));
    ns[i] = axis ? axes[i % 6] : glm::normalize(Vec3(u(rng) - 0.5f, u(rng) - 0.5f, u(rng) - 0.5f) + Vec3(0.f, 0.f, 1e-3f));
  }
  NeuralSite site;
  double best = 1e30, sink = 0.0;
  for (int r = 0; r < 30; ++r) {
    const auto t0 = std::chrono::steady_clock::now();
    for (int i = 0; i < kPoints; ++i) {
      neural_infer_cpu(v, ps[i], ns[i], &site);
      sink += site.irradiance;
    }
    best = std::min(best, std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
  }
  volatile double keep = sink;  // the results are used: the loop is not optimised away
  (void)keep;
  std::printf("%s normals, %u learned lights: %.0f ns per inference (best of 30 loops of %d; avx2 %s)\n",
              axis ? "axis-aligned" : "random", lights, best / kPoints * 1e9, kPoints,
              neural_infer_has_avx2() ? "yes" : "no");
  return 0;
}
