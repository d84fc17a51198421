// Pixel samplers: Owen-scrambled Sobol points are stratified in every 1D and
// 2D request for every power-of-two prefix of a pixel's samples, are
// decorrelated between requests and pixels, and are pure functions of
// (seed, pixel, sample, dimension).
#include <gtest/gtest.h>

#include <set>
#include <vector>

#include "kernels/sampler.h"

namespace tessera {
namespace {

// The `request`-th 2D request of samples 0..n-1 of one pixel.
std::vector<Vec2> points2d(uint64_t seed, uint64_t pixel, int request, uint32_t n, uint32_t first = 0) {
  std::vector<Vec2> out;
  for (uint32_t i = first; i < first + n; ++i) {
    PixelSampler s = PixelSampler::start(SamplerKind::Sobol, seed, pixel, i);
    Vec2 p(0.f);
    for (int r = 0; r <= request; ++r) p = s.uniform2();
    out.push_back(p);
  }
  return out;
}

// Every elementary interval of area 1/n (2^a x 2^b cells, a + b = log2 n) holds exactly one point.
bool is_02_net(const std::vector<Vec2>& pts) {
  const uint32_t n = static_cast<uint32_t>(pts.size());
  int m = 0;
  while ((1u << m) < n) ++m;
  for (int a = 0; a <= m; ++a) {
    const uint32_t nx = 1u << a, ny = 1u << (m - a);
    std::set<uint64_t> cells;
    for (const Vec2& p : pts) {
      const uint64_t cx = static_cast<uint64_t>(p.x * nx), cy = static_cast<uint64_t>(p.y * ny);
      if (!cells.insert(cy * nx + cx).second) return false;
    }
  }
  return true;
}

TEST(Sampler, SobolPrefixesAreZeroTwoNetsInEveryRequest) {
  for (int request : {0, 1, 5, 17}) {
    for (uint32_t n : {4u, 64u, 256u}) {
      SCOPED_TRACE(request);
      EXPECT_TRUE(is_02_net(points2d(3, 12345, request, n))) << n;
    }
    // The second block of 64 is a net too (passes of any length stay stratified).
    EXPECT_TRUE(is_02_net(points2d(3, 12345, request, 64, 64)));
  }
  // Independent numbers almost never form a net (the test can fail).
  std::vector<Vec2> random;
  for (uint32_t i = 0; i < 64; ++i) random.push_back(PixelSampler::start(SamplerKind::Independent, 3, 12345, i).uniform2());
  EXPECT_FALSE(is_02_net(random));
}

TEST(Sampler, SobolOneDimensionalRequestsAreStratified) {
  const uint32_t n = 128;
  for (int request : {0, 3}) {
    std::set<uint32_t> strata;
    for (uint32_t i = 0; i < n; ++i) {
      PixelSampler s = PixelSampler::start(SamplerKind::Sobol, 9, 77, i);
      Float u = 0.f;
      for (int r = 0; r <= request; ++r) u = s.uniform();
      ASSERT_GE(u, 0.f);
      ASSERT_LT(u, 1.f);
      strata.insert(static_cast<uint32_t>(u * n));
    }
    EXPECT_EQ(strata.size(), n) << request;
  }
}

TEST(Sampler, RequestsAndPixelsAreDecorrelated) {
  // Sample i's points in two requests (or two pixels) are not the same point
  // set in the same order: the correlation of x over 1024 samples is small.
  auto correlation = [](const std::vector<Vec2>& a, const std::vector<Vec2>& b) {
    double sab = 0, sa = 0, sb = 0, saa = 0, sbb = 0;
    const double n = static_cast<double>(a.size());
    for (size_t i = 0; i < a.size(); ++i) {
      sab += a[i].x * b[i].x;
      sa += a[i].x;
      sb += b[i].x;
      saa += a[i].x * a[i].x;
      sbb += b[i].x * b[i].x;
    }
    return (sab / n - sa / n * sb / n) / std::sqrt((saa / n - sa * sa / (n * n)) * (sbb / n - sb * sb / (n * n)));
  };
  const auto r0 = points2d(1, 5, 0, 1024), r1 = points2d(1, 5, 1, 1024), other_pixel = points2d(1, 6, 0, 1024);
  EXPECT_LT(std::abs(correlation(r0, r1)), 0.1);
  EXPECT_LT(std::abs(correlation(r0, other_pixel)), 0.1);
  // Same arguments, same numbers; another seed, other numbers.
  EXPECT_EQ(points2d(1, 5, 2, 8), points2d(1, 5, 2, 8));
  EXPECT_NE(points2d(1, 5, 2, 8), points2d(2, 5, 2, 8));
}

TEST(Sampler, SobolPointsAreUniformOnAverage) {
  // Over many pixels the mean of each coordinate is 1/2 and of its square 1/3.
  double sx = 0, sxx = 0, sy = 0;
  const int pixels = 2000, n = 16;
  for (int p = 0; p < pixels; ++p)
    for (const Vec2& v : points2d(4, p, 2, n)) {
      sx += v.x;
      sxx += v.x * v.x;
      sy += v.y;
    }
  const double count = pixels * n;
  EXPECT_NEAR(sx / count, 0.5, 0.005);
  EXPECT_NEAR(sy / count, 0.5, 0.005);
  EXPECT_NEAR(sxx / count, 1.0 / 3.0, 0.005);
}

}  // namespace
}  // namespace tessera
