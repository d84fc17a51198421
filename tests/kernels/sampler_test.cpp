// Pixel samplers: Owen-scrambled Sobol points (padded and z-ordered) are
// stratified in every 1D and 2D request for every power-of-two prefix of a
// pixel's samples; z-ordered ones also across aligned blocks of pixels;
// stratified ones put one sample in every stratum per round; Halton's
// leading digits pick the pixel and its randomised dimensions are stratified
// in every base-power prefix; all are
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
  s.halton = halton_layout(1000, 1000);  // start() below lays pixels out on a 1000-wide image
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

// pbrt-v4's Halton layout: the leading digits of pixel (x, y)'s indices, in
// bases 2 and 3, are x and y (modulo 128), so the global sequence's first two
// dimensions scaled by 2^a x 3^b land in the pixel: the radical inverse of
// the index times base^digits, in integers, is the pixel's coordinate.
TEST(Sampler, HaltonIndicesLandInTheirPixel) {
  auto scaled_radical_inverse = [](uint64_t a, uint32_t base, uint32_t digits) {
    uint64_t v = 0;
    for (uint32_t k = 0; k < digits; ++k, a /= base) v = v * base + a % base;
    return static_cast<uint32_t>(v);
  };
  const HaltonLayout l = halton_layout(300, 200);
  EXPECT_EQ(l.scale[0], 128u);
  EXPECT_EQ(l.scale[1], 243u);
  const HaltonLayout small = halton_layout(20, 7);
  EXPECT_EQ(small.scale[0], 32u);
  EXPECT_EQ(small.scale[1], 9u);
  for (const HaltonLayout& layout : {l, small}) {
    const uint64_t stride = static_cast<uint64_t>(layout.scale[0]) * layout.scale[1];
    const uint32_t w = layout.scale[0] < 128u ? 20u : 300u, h = layout.scale[1] < 27u ? 7u : 200u;
    for (uint32_t y = 0; y < h; ++y)
      for (uint32_t x = 0; x < w; ++x)
        for (uint64_t sample : {0ull, 1ull, 37ull}) {
          const uint64_t index = halton_pixel_index(layout, x, y) + sample * stride;
          ASSERT_EQ(scaled_radical_inverse(index, 2, layout.exponent[0]), x % 128u) << x << ',' << y;
          ASSERT_EQ(scaled_radical_inverse(index, 3, layout.exponent[1]), y % 128u) << x << ',' << y;
        }
  }
}

// A pixel's Halton samples: the point in the pixel is stratified in x over
// 2^k samples and in y over 3^k; a 1D request in base p over p^k samples and
// a 2D request in bases p, q over (p q)^k samples put one point in every
// cell (the sample stride 2^a 3^b is coprime to the other primes).
TEST(Sampler, HaltonPrefixesAreStratified) {
  for (HaltonRandomize r : {HaltonRandomize::PermuteDigits, HaltonRandomize::None, HaltonRandomize::Owen}) {
    SCOPED_TRACE(static_cast<int>(r));
    SamplerSetup setup = setup_of(SamplerKind::Halton, 3);
    setup.halton_randomize = r;
    auto cells = [&](uint32_t n, auto&& cell_of) {
      std::set<uint32_t> seen;
      for (uint32_t i = 0; i < n; ++i) {
        PixelSampler s = start(setup, 123457, i);
        seen.insert(cell_of(s));
      }
      return static_cast<uint32_t>(seen.size());
    };
    EXPECT_EQ(cells(64, [](PixelSampler& s) { return static_cast<uint32_t>(s.pixel2().x * 64); }), 64u);
    EXPECT_EQ(cells(81, [](PixelSampler& s) { return static_cast<uint32_t>(s.pixel2().y * 81); }), 81u);
    // Dimension 2 (base 5), then dimensions 3 and 4 (bases 7 and 11).
    EXPECT_EQ(cells(125, [](PixelSampler& s) { return static_cast<uint32_t>(s.uniform() * 125); }), 125u);
    EXPECT_EQ(cells(77, [](PixelSampler& s) {
                s.uniform();
                const Vec2 p = s.uniform2();
                return static_cast<uint32_t>(p.y * 11) * 7 + static_cast<uint32_t>(p.x * 7);
              }),
              77u);
    // The first 2D request is dimensions 2 and 3: 25 x 49 cells by 1225 samples.
    EXPECT_EQ(cells(1225, [](PixelSampler& s) {
                const Vec2 p = s.uniform2();
                return static_cast<uint32_t>(p.y * 49) * 25 + static_cast<uint32_t>(p.x * 25);
              }),
              1225u);
  }
  // The three randomisations give three point sets; "none" is the plain radical inverse.
  SamplerSetup setup = setup_of(SamplerKind::Halton, 3);
  Float firsts[3];
  for (int r = 0; r < 3; ++r) {
    setup.halton_randomize = static_cast<HaltonRandomize>(r);
    firsts[r] = start(setup, 123457, 5).uniform();
  }
  EXPECT_NE(firsts[0], firsts[1]);
  EXPECT_NE(firsts[0], firsts[2]);
  EXPECT_NE(firsts[1], firsts[2]);
  const uint64_t index = halton_pixel_index(setup.halton, 123457 % 1000, 123457 / 1000) +
                         5ull * setup.halton.scale[0] * setup.halton.scale[1];
  double plain = 0, f = 0.2;
  for (uint64_t i = index; i; i /= 5, f /= 5) plain += static_cast<double>(i % 5) * f;
  EXPECT_NEAR(firsts[1], plain, 1e-6);
  setup.halton_randomize = HaltonRandomize::PermuteDigits;
  // Past the 1000th prime the dimensions start again at 2, as pbrt-v4's do.
  PixelSampler a = start(setup, 9, 5), b = start(setup, 9, 5);
  const Float first = a.uniform();
  for (int i = 0; i < 998; ++i) b.uniform();  // dimensions 2..999
  EXPECT_EQ(b.uniform(), first);
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
  for (SamplerKind kind : {SamplerKind::Sobol, SamplerKind::ZSobol, SamplerKind::Stratified, SamplerKind::Halton}) {
    SCOPED_TRACE(static_cast<int>(kind));
    const auto r0 = points2d(1, 5, 0, 1024, 0, kind), r1 = points2d(1, 5, 1, 1024, 0, kind);
    const auto other_pixel = points2d(1, 6, 0, 1024, 0, kind);
    EXPECT_LT(std::abs(correlation(r0, r1)), 0.1);
    // Halton's pixels are residues of one sequence, as pbrt-v4's are: their
    // leading digits differ by a constant, so neighbours are not decorrelated.
    if (kind != SamplerKind::Halton) {
      EXPECT_LT(std::abs(correlation(r0, other_pixel)), 0.1);
    }
    // Same arguments, same numbers; another seed, other numbers.
    EXPECT_EQ(points2d(1, 5, 2, 8, 0, kind), points2d(1, 5, 2, 8, 0, kind));
    EXPECT_NE(points2d(1, 5, 2, 8, 0, kind), points2d(2, 5, 2, 8, 0, kind));
  }
}

TEST(Sampler, PointsAreUniformOnAverage) {
  // Over many pixels the mean of each coordinate is 1/2 and of its square 1/3.
  for (SamplerKind kind : {SamplerKind::Sobol, SamplerKind::ZSobol, SamplerKind::Stratified, SamplerKind::Halton}) {
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
