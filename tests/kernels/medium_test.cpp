// The Henyey-Greenstein phase function (pbrt-v4's convention: wo points back
// along the path) and collision sampling in homogeneous media.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "kernels/grid_medium.h"
#include "kernels/medium.h"
#include "kernels/rng.h"

namespace tessera {
namespace {

const Vec3 kWo = glm::normalize(Vec3(0.3f, -0.5f, 0.8f));

TEST(HenyeyGreenstein, IntegratesToOneAndHasMeanCosineG) {
  for (Float g : {-0.8f, -0.3f, 0.f, 0.5f, 0.9f}) {
    // Midpoint rule over mu = cos(-wo, wi); the pdf depends on mu alone.
    const int n = 200000;
    double integral = 0, mean_cos = 0;
    for (int i = 0; i < n; ++i) {
      const double mu = -1.0 + 2.0 * (i + 0.5) / n;
      const double p = henyey_greenstein(static_cast<Float>(-mu), g) * 2.0 * M_PI * (2.0 / n);
      integral += p;
      mean_cos += mu * p;
    }
    EXPECT_NEAR(integral, 1.0, 1e-3) << "g " << g;
    EXPECT_NEAR(mean_cos, g, 2e-3) << "g " << g;  // g > 0: forward, towards -wo
  }
}

TEST(HenyeyGreenstein, IsReciprocal) {
  const Vec3 wi = glm::normalize(Vec3(-0.2f, 0.9f, 0.1f));
  EXPECT_FLOAT_EQ(henyey_greenstein(glm::dot(kWo, wi), 0.7f), henyey_greenstein(glm::dot(wi, kWo), 0.7f));
}

TEST(HenyeyGreenstein, SamplesFollowThePdf) {
  // Chi-square over 40 bins of mu = cos(-wo, wi), with the pdf the sampler returns checked too.
  for (Float g : {-0.7f, 0.f, 0.3f, 0.95f}) {
    const int bins = 40, n = 400000;
    std::vector<double> observed(bins, 0.0);
    Rng rng = Rng::for_sample(1, 2, 3);
    for (int i = 0; i < n; ++i) {
      Float pdf = 0.f;
      const Vec3 wi = sample_henyey_greenstein(kWo, g, rng.uniform2(), &pdf);
      ASSERT_NEAR(glm::length(wi), 1.f, 1e-4f);
      ASSERT_NEAR(pdf, henyey_greenstein(glm::dot(kWo, wi), g), 1e-3f * pdf + 1e-5f);
      const double mu = glm::clamp(-glm::dot(kWo, wi), -1.f, 1.f);
      observed[std::min(bins - 1, static_cast<int>((mu + 1.0) / 2.0 * bins))] += 1.0;
    }
    double chi2 = 0;
    for (int b = 0; b < bins; ++b) {
      // Expected count: the pdf integrated over the bin (fine midpoint rule).
      double p = 0;
      const int sub = 2000;
      for (int k = 0; k < sub; ++k) {
        const double mu = -1.0 + 2.0 * (b + (k + 0.5) / sub) / bins;
        p += henyey_greenstein(static_cast<Float>(-mu), g) * 2.0 * M_PI * (2.0 / bins / sub);
      }
      const double expected = p * n;
      chi2 += (observed[b] - expected) * (observed[b] - expected) / expected;
    }
    EXPECT_LT(chi2, 80.0) << "g " << g;  // 39 dof: p < 1e-4 beyond ~80
  }
}

TEST(MediumSegment, EstimatesTransmittanceAndScatteringInEveryChannel) {
  // E[weight | reached t_max] P = T(t_max); E[weight | collided] P = albedo (1 - T):
  // for a chromatic medium where one channel has no extinction at all.
  Medium m;
  m.sigma_a = Rgb(0.f, 0.2f, 0.5f);
  m.sigma_s = Rgb(0.f, 0.6f, 1.5f);
  const Float t_max = 1.3f;
  const int n = 1000000;
  Rgb reach(0.f), scatter(0.f);
  Rng rng = Rng::for_sample(7, 8, 9);
  for (int i = 0; i < n; ++i) {
    const MediumSegment seg = sample_medium_segment(m, t_max, rng.uniform(), rng.uniform());
    ASSERT_TRUE(std::isfinite(seg.weight.x) && std::isfinite(seg.weight.y) && std::isfinite(seg.weight.z));
    (seg.scattered ? scatter : reach) += seg.weight;
  }
  reach /= static_cast<Float>(n);
  scatter /= static_cast<Float>(n);
  const Rgb sigma_t = m.sigma_a + m.sigma_s;
  for (int c = 0; c < 3; ++c) {
    const double T = std::exp(-sigma_t[c] * t_max);
    EXPECT_NEAR(reach[c], T, 0.005) << "channel " << c;
    const double albedo = sigma_t[c] > 0.f ? m.sigma_s[c] / sigma_t[c] : 0.0;
    EXPECT_NEAR(scatter[c], albedo * (1.0 - T), 0.005) << "channel " << c;
  }
}

TEST(MediumSegment, AnInfiniteSegmentAlwaysCollidesWhereEveryChannelExtinguishes) {
  Medium m;
  m.sigma_s = Rgb(0.1f, 0.2f, 0.3f);
  Rng rng = Rng::for_sample(1, 1, 1);
  for (int i = 0; i < 1000; ++i) EXPECT_TRUE(sample_medium_segment(m, kInfinity, rng.uniform(), rng.uniform()).scattered);
}

}  // namespace
}  // namespace tessera

namespace tessera {
namespace {

// A 2 x 1 x 1 grid over [0,2] x [0,1] x [0,1]: values 0 and 1 at x = 0.5 and 1.5.
DensityGridView two_voxels(const Float* values) {
  DensityGridView g;
  g.p0 = Vec3(0.f);
  g.p1 = Vec3(2.f, 1.f, 1.f);
  g.nx = 2;
  g.density = values;
  g.max_density = 1.f;
  return g;
}

TEST(GridMedium, DensityIsTrilinearBetweenVoxelCentresAndZeroOutside) {
  const Float values[2] = {0.f, 1.f};
  const DensityGridView g = two_voxels(values);
  EXPECT_FLOAT_EQ(grid_density(g, Vec3(0.5f, 0.5f, 0.5f)), 0.f);
  EXPECT_FLOAT_EQ(grid_density(g, Vec3(1.5f, 0.5f, 0.5f)), 1.f);
  EXPECT_FLOAT_EQ(grid_density(g, Vec3(1.0f, 0.5f, 0.5f)), 0.5f);
  EXPECT_FLOAT_EQ(grid_density(g, Vec3(1.75f, 0.5f, 0.5f)), 0.75f);  // towards the zero beyond the last voxel
  EXPECT_FLOAT_EQ(grid_density(g, Vec3(1.5f, 0.25f, 0.5f)), 0.75f);
  EXPECT_EQ(grid_density(g, Vec3(2.5f, 0.5f, 0.5f)), 0.f);
  EXPECT_EQ(grid_density(g, Vec3(-1.f, 0.5f, 0.5f)), 0.f);
}

// A 4^3 grid of ones over [-4, 4]^3: exactly 1 within [-3, 3]^3 (between
// the outer voxel centres).
struct ConstantGrid {
  std::vector<Float> ones = std::vector<Float>(64, 1.f);
  DensityGridView g;
  ConstantGrid() {
    g.p0 = Vec3(-4.f);
    g.p1 = Vec3(4.f);
    g.nx = g.ny = g.nz = 4;
    g.density = ones.data();
    g.max_density = 1.f;
  }
};

TEST(GridMedium, RatioTrackingEstimatesTheTransmittance) {
  ConstantGrid c;
  Medium m;
  m.sigma_a = Rgb(0.1f, 0.3f, 0.6f);
  m.sigma_s = Rgb(0.1f, 0.2f, 0.0f);
  m.grid = 0;
  const Float d = 2.5f;
  Rgb sum(0.f);
  const int n = 200000;
  Rng rng = Rng::for_sample(3, 4, 5);
  for (int i = 0; i < n; ++i) {
    const Vec3 o(rng.uniform() - 0.5f, rng.uniform() - 0.5f, -1.f);
    sum += grid_transmittance(m, c.g, o, Vec3(0.f, 0.f, 1.f), d);
  }
  const Rgb mean = sum / static_cast<Float>(n);
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(mean[k], std::exp(-(m.sigma_a[k] + m.sigma_s[k]) * d), 0.004) << k;
}

TEST(GridMedium, DeltaTrackingEstimatesTransmittanceAndScatteringInEveryChannel) {
  ConstantGrid c;
  Medium m;
  m.sigma_a = Rgb(0.f, 0.2f, 0.5f);
  m.sigma_s = Rgb(0.f, 0.6f, 1.5f);
  m.grid = 0;
  const Float t_max = 1.3f;
  const int n = 400000;
  Rgb reach(0.f), scatter(0.f);
  Rng rng = Rng::for_sample(7, 8, 9);
  for (int i = 0; i < n; ++i) {
    const Vec3 o(rng.uniform() - 0.5f, rng.uniform() - 0.5f, -1.f);
    const MediumSegment seg = sample_grid_segment(m, c.g, o, Vec3(0.f, 0.f, 1.f), t_max, rng.uniform());
    ASSERT_TRUE(std::isfinite(seg.weight.x) && std::isfinite(seg.weight.y) && std::isfinite(seg.weight.z));
    (seg.scattered ? scatter : reach) += seg.weight;
  }
  reach /= static_cast<Float>(n);
  scatter /= static_cast<Float>(n);
  for (int k = 0; k < 3; ++k) {
    const double sigma_t = m.sigma_a[k] + m.sigma_s[k];
    const double T = std::exp(-sigma_t * t_max);
    EXPECT_NEAR(reach[k], T, 0.006) << "channel " << k;
    const double albedo = sigma_t > 0 ? m.sigma_s[k] / sigma_t : 0.0;
    EXPECT_NEAR(scatter[k], albedo * (1.0 - T), 0.006) << "channel " << k;
  }
}

TEST(GridMedium, RaysMissingTheBoxSeeNoMedium) {
  ConstantGrid c;
  Medium m;
  m.sigma_s = Rgb(1.f);
  m.grid = 0;
  EXPECT_EQ(grid_transmittance(m, c.g, Vec3(10.f, 0.f, 0.f), Vec3(0.f, 0.f, 1.f), 100.f), Rgb(1.f));
  const MediumSegment seg = sample_grid_segment(m, c.g, Vec3(10.f, 0.f, 0.f), Vec3(0.f, 0.f, 1.f), kInfinity, 0.3f);
  EXPECT_FALSE(seg.scattered);
  EXPECT_EQ(seg.weight, Rgb(1.f));
}

}  // namespace
}  // namespace tessera
