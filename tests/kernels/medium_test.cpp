// The Henyey-Greenstein phase function (pbrt-v4's convention: wo points back
// along the path) and collision sampling in homogeneous media.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

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
  glm::dvec3 reach(0.0), scatter(0.0);  // (a float sum of a million weights drifts by ~0.5 %)
  Rng rng = Rng::for_sample(7, 8, 9);
  for (int i = 0; i < n; ++i) {
    HeroChannels h;  // a fresh path: its first segment
    choose_hero(h, rng.uniform());
    const MediumSegment seg = sample_medium_segment(m, t_max, h, rng.uniform());
    ASSERT_TRUE(std::isfinite(seg.weight.x) && std::isfinite(seg.weight.y) && std::isfinite(seg.weight.z));
    (seg.scattered ? scatter : reach) += glm::dvec3(seg.weight);
  }
  reach /= static_cast<double>(n);
  scatter /= static_cast<double>(n);
  const Rgb sigma_t = m.sigma_a + m.sigma_s;
  for (int c = 0; c < 3; ++c) {
    const double T = std::exp(-sigma_t[c] * t_max);
    EXPECT_NEAR(reach[c], T, 0.005) << "channel " << c;
    const double albedo = sigma_t[c] > 0.f ? m.sigma_s[c] / sigma_t[c] : 0.0;
    EXPECT_NEAR(scatter[c], albedo * (1.0 - T), 0.005) << "channel " << c;
  }
}

// Three segments chained on one path (one hero, its relative pdfs carried
// from segment to segment): for each pattern of collided / passed segments,
// E[product of weights] is the product of each segment's T or albedo (1 - T),
// per channel. (A fresh path per segment, as above, cannot see the carry.)
TEST(MediumSegment, ChainedSegmentsStayUnbiasedForEveryPattern) {
  Medium m;
  m.sigma_a = Rgb(0.05f, 0.3f, 0.2f);
  m.sigma_s = Rgb(0.1f, 0.9f, 2.4f);
  const Float t_max = 1.1f;
  const int n = 1000000, segments = 3;
  glm::dvec3 sum[8], sum2[8];
  for (int k = 0; k < 8; ++k) sum[k] = sum2[k] = glm::dvec3(0.0);
  Rng rng = Rng::for_sample(3, 1, 4);
  for (int i = 0; i < n; ++i) {
    HeroChannels h;
    choose_hero(h, rng.uniform());
    glm::dvec3 w(1.0);
    int pattern = 0;
    for (int j = 0; j < segments; ++j) {
      const MediumSegment seg = sample_medium_segment(m, t_max, h, rng.uniform());
      w *= glm::dvec3(seg.weight);
      pattern |= (seg.scattered ? 1 : 0) << j;
    }
    sum[pattern] += w;
    sum2[pattern] += w * w;
  }
  const Rgb sigma_t = m.sigma_a + m.sigma_s;
  for (int k = 0; k < 8; ++k)
    for (int c = 0; c < 3; ++c) {
      const double T = std::exp(-sigma_t[c] * t_max), collide = m.sigma_s[c] / sigma_t[c] * (1.0 - T);
      double want = 1.0;
      for (int j = 0; j < segments; ++j) want *= ((k >> j) & 1) ? collide : T;
      const double mean = sum[k][c] / n, se = std::sqrt(std::max(0.0, sum2[k][c] / n - mean * mean) / n);
      EXPECT_NEAR(mean, want, 4.0 * se + 1e-4 * want) << "pattern " << k << " channel " << c;
    }
}

TEST(MediumSegment, AnInfiniteSegmentAlwaysCollidesWhereEveryChannelExtinguishes) {
  Medium m;
  m.sigma_s = Rgb(0.1f, 0.2f, 0.3f);
  Rng rng = Rng::for_sample(1, 1, 1);
  for (int i = 0; i < 1000; ++i) {
    HeroChannels h;
    choose_hero(h, rng.uniform());
    EXPECT_TRUE(sample_medium_segment(m, kInfinity, h, rng.uniform()).scattered);
  }
}

}  // namespace
}  // namespace tessera
