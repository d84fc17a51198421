// Pixel samplers: Owen-scrambled Sobol points (padded and z-ordered) are
// stratified in every 1D and 2D request for every power-of-two prefix of a
// pixel's samples; z-ordered ones also across aligned blocks of pixels;
// stratified ones put one sample in every stratum per round; all are
// decorrelated between requests and pixels, uniform on average, and pure
// functions of (seed, pixel, sample, dimension).
#include <gtest/gtest.h>

#include <cmath>
#include <set>
#include <vector>

#include "kernels/sampler.h"

namespace tessera {
namespace {

SamplerSetup setup_of(SamplerKind kind, uint64_t seed, uint32_t log2_spp = 8) {
  SamplerSetup s;
  s.kind = kind;
  s.seed = seed;
  s.log2_spp = log2_spp;
  s.strata_x = 8;
  s.strata_y = 4;
  return s;
}

// Pixel `pixel` of a 1000-pixel-wide image.
PixelSampler start(const SamplerSetup& setup, uint64_t pixel, uint64_t sample) {
  return PixelSampler::start(setup, static_cast<uint32_t>(pixel % 1000), static_cast<uint32_t>(pixel / 1000), pixel,
                             sample);
}

// The `request`-th 2D request of samples first..first+n-1 of one pixel.
std::vector<Vec2> points2d(uint64_t seed, uint64_t pixel, int request, uint32_t n, uint32_t first = 0,
                           SamplerKind kind = SamplerKind::Sobol) {
  std::vector<Vec2> out;
  for (uint32_t i = first; i < first + n; ++i) {
    PixelSampler s = start(setup_of(kind, seed), pixel, i);
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

// The closed form of Sobol's second dimension equals the generator matrix
// applied bit by bit (direction numbers m_k = m_{k-1} xor 2 m_{k-1}).
TEST(Sampler, SobolSecondDimensionMatchesItsDirectionNumbers) {
  auto by_loop = [](uint32_t index) {
    uint32_t v = 0, direction = 0x80000000u;
    for (; index != 0; index >>= 1, direction ^= direction >> 1)
      if (index & 1u) v ^= direction;
    return v;
  };
  Rng rng = Rng::for_sample(1, 2, 3);
  for (uint32_t i = 0; i < 4096; ++i) EXPECT_EQ(sobol_detail::sobol_dim1(i), by_loop(i)) << i;
  for (int k = 0; k < 100000; ++k) {
    const uint32_t i = rng.next_u32();
    ASSERT_EQ(sobol_detail::sobol_dim1(i), by_loop(i)) << i;
  }
}

TEST(Sampler, SobolPrefixesAreZeroTwoNetsInEveryRequest) {
  for (SamplerKind kind : {SamplerKind::Sobol, SamplerKind::ZSobol}) {
    for (int request : {0, 1, 5, 17}) {
      SCOPED_TRACE(request);
      for (uint32_t n : {4u, 8u, 32u, 64u, 128u, 256u}) EXPECT_TRUE(is_02_net(points2d(3, 12345, request, n, 0, kind))) << n;
      // The second block of 64 is a net too (passes of any length stay stratified).
      EXPECT_TRUE(is_02_net(points2d(3, 12345, request, 64, 64, kind)));
      // Past the scene's sample count (2^8 here) a new epoch is a net of its own.
      EXPECT_TRUE(is_02_net(points2d(3, 12345, request, 64, 256, kind)));
    }
  }
  // Independent numbers almost never form a net (the test can fail).
  std::vector<Vec2> random;
  for (uint32_t i = 0; i < 64; ++i) random.push_back(start(setup_of(SamplerKind::Independent, 3), 12345, i).uniform2());
  EXPECT_FALSE(is_02_net(random));
}

// pbrt-v4's zsobol: the samples of an aligned 2^k x 2^k block of pixels are
// one block of the Sobol sequence, so together they are a net too: the
// pixels' errors are spread like blue noise instead of independently.
TEST(Sampler, ZSobolPixelBlocksTogetherAreZeroTwoNets) {
  for (uint32_t log2_spp : {0u, 1u, 2u, 4u}) {
    for (int request : {0, 3}) {
      for (uint32_t side : {2u, 4u}) {
        std::vector<Vec2> zsobol, padded;
        for (uint32_t y = 8; y < 8 + side; ++y)
          for (uint32_t x = 4; x < 4 + side; ++x)
            for (uint32_t i = 0; i < (1u << log2_spp); ++i)
              for (SamplerKind kind : {SamplerKind::ZSobol, SamplerKind::Sobol}) {
                PixelSampler s = PixelSampler::start(setup_of(kind, 7, log2_spp), x, y, y * 1000 + x, i);
                Vec2 p(0.f);
                for (int r = 0; r <= request; ++r) p = s.uniform2();
                (kind == SamplerKind::ZSobol ? zsobol : padded).push_back(p);
              }
        EXPECT_TRUE(is_02_net(zsobol)) << log2_spp << " " << request << " " << side;
        if (zsobol.size() >= 16) {
          EXPECT_FALSE(is_02_net(padded)) << "pixels drawn independently are not one net";
        }
      }
    }
  }
}

TEST(Sampler, SobolOneDimensionalRequestsAreStratified) {
  const uint32_t n = 128;
  for (SamplerKind kind : {SamplerKind::Sobol, SamplerKind::ZSobol}) {
    for (int request : {0, 3}) {
      std::set<uint32_t> strata;
      for (uint32_t i = 0; i < n; ++i) {
        PixelSampler s = start(setup_of(kind, 9), 77, i);
        Float u = 0.f;
        for (int r = 0; r <= request; ++r) u = s.uniform();
        ASSERT_GE(u, 0.f);
        ASSERT_LT(u, 1.f);
        strata.insert(static_cast<uint32_t>(u * n));
      }
      EXPECT_EQ(strata.size(), n) << request;
    }
  }
}

// pbrt-v4's stratified sampler: every round of xsamples * ysamples samples
// puts one sample in every 2D stratum and one in every 1D stratum, each
// request visiting the strata in its own order.
TEST(Sampler, StratifiedRoundsFillEveryStratumOnce) {
  const SamplerSetup setup = setup_of(SamplerKind::Stratified, 5);  // 8 x 4 strata
  const uint32_t n = 32;
  for (uint32_t round = 0; round < 3; ++round) {
    std::set<uint32_t> cells2, cells1, first_request;
    for (uint32_t i = round * n; i < (round + 1) * n; ++i) {
      PixelSampler s = start(setup, 4242, i);
      const Vec2 p = s.uniform2();
      first_request.insert(static_cast<uint32_t>(p.y * 4) * 8 + static_cast<uint32_t>(p.x * 8));
      const Float u = s.uniform();
      const Vec2 q = s.uniform2();
      ASSERT_TRUE(u >= 0.f && u < 1.f && q.x >= 0.f && q.x < 1.f && q.y >= 0.f && q.y < 1.f);
      cells1.insert(static_cast<uint32_t>(u * n));
      cells2.insert(static_cast<uint32_t>(q.y * 4) * 8 + static_cast<uint32_t>(q.x * 8));
    }
    EXPECT_EQ(first_request.size(), n);
    EXPECT_EQ(cells1.size(), n);
    EXPECT_EQ(cells2.size(), n);
  }
  // Without jitter every point is its stratum's centre.
  SamplerSetup centred = setup;
  centred.jitter = false;
  const Vec2 c = start(centred, 1, 3).uniform2();
  EXPECT_FLOAT_EQ(c.x * 8 - std::floor(c.x * 8), 0.5f);
  EXPECT_FLOAT_EQ(c.y * 4 - std::floor(c.y * 4), 0.5f);
}

TEST(Sampler, PermutationElementIsAPermutation) {
  for (uint32_t n : {1u, 2u, 3u, 7u, 32u, 100u, 1000u}) {
    for (uint64_t key : {0ull, 1ull, 0x123456789abcdefull}) {
      std::set<uint32_t> seen;
      for (uint32_t i = 0; i < n; ++i) seen.insert(permutation_element(i, n, key));
      EXPECT_EQ(seen.size(), n);
      EXPECT_LT(*seen.rbegin(), n);
    }
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
  for (SamplerKind kind : {SamplerKind::Sobol, SamplerKind::ZSobol, SamplerKind::Stratified}) {
    SCOPED_TRACE(static_cast<int>(kind));
    const auto r0 = points2d(1, 5, 0, 1024, 0, kind), r1 = points2d(1, 5, 1, 1024, 0, kind);
    const auto other_pixel = points2d(1, 6, 0, 1024, 0, kind);
    EXPECT_LT(std::abs(correlation(r0, r1)), 0.1);
    EXPECT_LT(std::abs(correlation(r0, other_pixel)), 0.1);
    // Same arguments, same numbers; another seed, other numbers.
    EXPECT_EQ(points2d(1, 5, 2, 8, 0, kind), points2d(1, 5, 2, 8, 0, kind));
    EXPECT_NE(points2d(1, 5, 2, 8, 0, kind), points2d(2, 5, 2, 8, 0, kind));
  }
}

TEST(Sampler, PointsAreUniformOnAverage) {
  // Over many pixels the mean of each coordinate is 1/2 and of its square 1/3.
  for (SamplerKind kind : {SamplerKind::Sobol, SamplerKind::ZSobol, SamplerKind::Stratified}) {
    double sx = 0, sxx = 0, sy = 0;
    const int pixels = 2000, n = 16;
    for (int p = 0; p < pixels; ++p)
      for (const Vec2& v : points2d(4, p, 2, n, 0, kind)) {
        sx += v.x;
        sxx += v.x * v.x;
        sy += v.y;
      }
    const double count = pixels * n;
    EXPECT_NEAR(sx / count, 0.5, 0.005) << static_cast<int>(kind);
    EXPECT_NEAR(sy / count, 0.5, 0.005) << static_cast<int>(kind);
    EXPECT_NEAR(sxx / count, 1.0 / 3.0, 0.005) << static_cast<int>(kind);
  }
}

}  // namespace
}  // namespace tessera
