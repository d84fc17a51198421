// pbrt-v4's gradient noise: zero on the lattice, bounded, continuous,
// periodic in 256, and safe on any input.
#include <gtest/gtest.h>

#include <cmath>

#include "kernels/perlin_noise.h"
#include "kernels/rng.h"

namespace tessera {
namespace {

TEST(PerlinNoise, ZeroOnTheLatticeBoundedAndCentred) {
  for (int x = -3; x <= 3; ++x)
    for (int y = -3; y <= 3; ++y)
      for (int z = -3; z <= 3; ++z) EXPECT_EQ(perlin_noise(Vec3(x, y, z)), 0.f);
  Rng rng = Rng::for_sample(1, 2, 3);
  double sum = 0.0, sum2 = 0.0;
  const int n = 200000;
  for (int i = 0; i < n; ++i) {
    const Vec3 p(rng.uniform() * 64.f - 32.f, rng.uniform() * 64.f - 32.f, rng.uniform() * 64.f - 32.f);
    const Float v = perlin_noise(p);
    ASSERT_LE(std::abs(v), 1.05f) << i;
    sum += v;
    sum2 += v * v;
  }
  EXPECT_NEAR(sum / n, 0.0, 0.01);
  EXPECT_GT(sum2 / n, 0.01);  // not flat
}

// Values of pbrt-v4's Noise() (src/pbrt/util/noise.cpp) at float inputs,
// computed in double by a separate transcription of it; (3.14, 42, 7) is
// also Perlin's own reference value (0.136919958784).
TEST(PerlinNoise, MatchesPbrtV4sNoiseAtReferencePoints) {
  EXPECT_NEAR(perlin_noise(Vec3(0.5f, 0.5f, 0.5f)), -0.1250000f, 2e-6f);
  EXPECT_NEAR(perlin_noise(Vec3(3.14f, 42.f, 7.f)), 0.1369201f, 2e-6f);
  EXPECT_NEAR(perlin_noise(Vec3(-1.3f, 2.7f, -0.4f)), 0.2085486f, 2e-6f);
  EXPECT_NEAR(perlin_noise(Vec3(17.25f, -8.5f, 100.125f)), -0.0704209f, 2e-6f);
  EXPECT_NEAR(perlin_noise(Vec3(0.1f, 0.9f, 0.33f)), 0.1136272f, 2e-6f);
}

TEST(PerlinNoise, ContinuousAndPeriodicIn256) {
  Rng rng = Rng::for_sample(4, 5, 6);
  for (int i = 0; i < 20000; ++i) {
    const Vec3 p(rng.uniform() * 20.f, rng.uniform() * 20.f, rng.uniform() * 20.f);
    const Vec3 step(1e-3f, -1e-3f, 1e-3f);
    ASSERT_NEAR(perlin_noise(p), perlin_noise(p + step), 0.02f) << i;
    ASSERT_NEAR(perlin_noise(p), perlin_noise(p + Vec3(256.f, 0.f, -256.f)), 1e-3f) << i;
  }
}

TEST(PerlinNoise, GradientIsTheForwardDifference) {
  const Vec3 p(1.3f, 2.7f, -0.4f);
  const Vec3 g = perlin_noise_gradient(p);
  EXPECT_FLOAT_EQ(g.x, (perlin_noise(p + Vec3(0.01f, 0.f, 0.f)) - perlin_noise(p)) / 0.01f);
  EXPECT_FLOAT_EQ(g.z, (perlin_noise(p + Vec3(0.f, 0.f, 0.01f)) - perlin_noise(p)) / 0.01f);
}

TEST(PerlinNoise, HugeAndNanInputsReadZero) {
  EXPECT_EQ(perlin_noise(Vec3(1e30f, 0.5f, 0.5f)), 0.f);
  EXPECT_EQ(perlin_noise(Vec3(-3e9f, 0.5f, 0.5f)), 0.f);
  EXPECT_EQ(perlin_noise(Vec3(std::nanf(""), 0.5f, 0.5f)), 0.f);
  EXPECT_TRUE(std::isfinite(perlin_noise(Vec3(-16777215.f, 0.5f, 0.25f))));
}

}  // namespace
}  // namespace tessera
