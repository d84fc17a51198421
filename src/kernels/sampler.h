// The random numbers of one pixel sample, drawn dimension by dimension: a pure
// function of (seed, pixel, sample index, dimension), so that any thread or
// rank renders the same image.
//
// The kinds follow pbrt-v4's Sampler directive:
// * Independent: PCG32 (pbrt-v4's IndependentSampler).
// * Sobol ("paddedsobol"; also pbrt's global "sobol", whose pixel ordering we
//   do not reproduce): every 1D and 2D request is the next point of the first
//   two Sobol dimensions with Owen scrambling, and the sample index itself
//   Owen-shuffled, seeds hashed from (seed, pixel, dimension). Every
//   power-of-two prefix of a pixel's samples is stratified in each request.
// * ZSobol (pbrt-v4's default): the same points, but all pixels share one
//   Sobol sequence in Morton order, the index Owen-scrambled per request
//   (zsobol_index.h): the pixel's own samples are as well stratified, and
//   neighbouring pixels' errors are spread like blue noise.
// * Stratified: sx x sy jittered strata in every 2D request and sx * sy in
//   every 1D one, the strata of each dimension visited in a random order
//   (pbrt-v4's StratifiedSampler); past sx * sy samples the next round uses
//   fresh orders.
// * Halton: pbrt-v4's HaltonSampler layout, one global sequence whose bases 2
//   and 3 pick the pixel and the point inside it (pixel2()), digits of the
//   other dimensions randomised per dimension (halton.h).
#pragma once

#include "halton.h"
#include "rng.h"
#include "sobol_points.h"
#include "zsobol_index.h"

namespace tessera {

enum class SamplerKind : uint32_t { Independent = 0, Sobol = 1, ZSobol = 2, Stratified = 3, Halton = 4 };

// What a render's sampler needs beside the pixel and sample: one per render.
struct SamplerSetup {
  SamplerKind kind = SamplerKind::ZSobol;
  uint64_t seed = 0;
  uint32_t log2_spp = 4;   // ZSobol: samples per epoch = 2^log2_spp (the scene's pixelsamples, rounded up)
  uint32_t strata_x = 4;   // Stratified: strata per pixel along x and y
  uint32_t strata_y = 4;
  bool jitter = true;      // Stratified: a random point in each stratum (else its centre)
  HaltonLayout halton;     // Halton: the image's pixel layout (halton_layout of the film's full resolution)
  HaltonRandomize halton_randomize = HaltonRandomize::PermuteDigits;
};

// The smallest L with 2^L >= spp, at most 26: the Sobol points use 32 bits
// of the index, and L + 6 of them must stay below the 8 x 8 pixel block
// whose bits seed the scramble (more samples start new epochs).
TESSERA_HOST_DEVICE inline uint32_t ceil_log2_spp(uint64_t spp) {
  uint32_t l = 0;
  while (l < 26u && (1ull << l) < spp) ++l;
  return l;
}

// Element i of a random permutation of [0, n), chosen by `key`: a bijective
// hash on the smallest power-of-two domain holding n (xor, odd multiplies and
// xor-shifts modulo 2^w are each invertible), walked until it lands in range.
TESSERA_HOST_DEVICE inline uint32_t permutation_element(uint32_t i, uint32_t n, uint64_t key) {
  if (n <= 1u) return 0u;
  uint32_t mask = n - 1u;
  mask |= mask >> 1;
  mask |= mask >> 2;
  mask |= mask >> 4;
  mask |= mask >> 8;
  mask |= mask >> 16;
  const uint32_t k0 = static_cast<uint32_t>(key), k1 = static_cast<uint32_t>(key >> 32);
  do {
    i ^= k0;
    i *= 0xe170893du;
    i ^= k1;
    i ^= (i & mask) >> 4;
    i ^= k0 >> 16;
    i *= 0x0929eb3fu;
    i ^= k1 >> 16;
    i ^= (i & mask) >> 1;
    i *= 1u | (k0 >> 27);
    i *= 0x6935fa69u;
    i ^= (i & mask) >> 11;
    i *= 0x74dcb303u;
    i ^= (i & mask) >> 2;
    i *= 0x9e501cc3u;
    i ^= (i & mask) >> 2;
    i *= 0xc860a3dfu;
    i &= mask;
    i ^= i >> 5;
  } while (i >= n);
  return i;
}

struct PixelSampler {
  SamplerKind kind = SamplerKind::Independent;
  Rng rng;                 // Independent
  uint64_t stream = 0;     // Sobol, Stratified: hash of (seed, pixel); ZSobol: hash of the seed
  uint64_t morton = 0;     // ZSobol: the pixel's Morton code
  uint64_t halton_index = 0;  // Halton: the sample's index in the global sequence
  uint32_t halton_exponent2 = 0, halton_scale3 = 1;  // Halton: the layout's 2^a and 3^b (pixel2)
  HaltonRandomize halton_randomize = HaltonRandomize::PermuteDigits;
  uint32_t index = 0;      // sample index within the pixel (ZSobol, Stratified: within its epoch)
  uint32_t epoch = 0;      // ZSobol, Stratified: which round of 2^L (sx * sy) samples
  uint32_t dimension = 0;
  uint32_t log2_spp = 0;
  uint32_t strata_x = 1, strata_y = 1;
  bool jitter = true;

  TESSERA_HOST_DEVICE static PixelSampler start(const SamplerSetup& setup, uint32_t x, uint32_t y, uint64_t pixel,
                                                uint64_t sample) {
    PixelSampler s;
    s.kind = setup.kind;
    switch (setup.kind) {
      case SamplerKind::Independent:
        s.rng = Rng::for_sample(setup.seed, pixel, sample);
        break;
      case SamplerKind::Sobol:
        s.stream = hash_stream(setup.seed, pixel, 0x50b01ull);
        s.index = static_cast<uint32_t>(sample);
        break;
      case SamplerKind::ZSobol:
        s.stream = mix_bits(setup.seed ^ 0x7a50b01ull);
        s.morton = zsobol_detail::morton2(x, y);
        s.log2_spp = setup.log2_spp;
        s.index = static_cast<uint32_t>(sample & ((1ull << setup.log2_spp) - 1ull));
        s.epoch = static_cast<uint32_t>(sample >> setup.log2_spp);
        break;
      case SamplerKind::Stratified: {
        const uint64_t n = static_cast<uint64_t>(setup.strata_x) * setup.strata_y;
        s.stream = hash_stream(setup.seed, pixel, 0x57a7ull);
        s.strata_x = setup.strata_x;
        s.strata_y = setup.strata_y;
        s.jitter = setup.jitter;
        s.index = static_cast<uint32_t>(sample % n);
        s.epoch = static_cast<uint32_t>(sample / n);
        break;
      }
      case SamplerKind::Halton:
        s.stream = mix_bits(setup.seed ^ 0x4a1709ull);
        s.halton_exponent2 = setup.halton.exponent[0];
        s.halton_scale3 = setup.halton.scale[1];
        s.halton_randomize = setup.halton_randomize;
        s.halton_index = halton_pixel_index(setup.halton, x, y) +
                         sample * (static_cast<uint64_t>(setup.halton.scale[0]) * setup.halton.scale[1]);
        s.dimension = 2;  // 0 and 1 are the pixel's (pixel2)
        break;
    }
    return s;
  }

  TESSERA_HOST_DEVICE Float uniform() {
    using namespace sobol_detail;
    switch (kind) {
      case SamplerKind::Independent:
        return rng.uniform();
      case SamplerKind::Sobol:
        return sobol_uniform();
      case SamplerKind::ZSobol: {
        // One Owen scramble per request for each aligned 8 x 8 block of
        // pixels (the bits above them): pbrt-v4 shares one over the whole
        // image, which correlates requests image-wide on some seeds
        // (material-testball: 1.5x the error on two seeds of six).
        const uint64_t key = dimension_hash();
        const uint64_t i = zsobol_detail::permuted_index(morton, index, log2_spp, key);
        return scrambled_dim0(static_cast<uint32_t>(i), static_cast<uint32_t>(mix_bits(key ^ (i >> (log2_spp + 6)))));
      }
      case SamplerKind::Stratified:
        return stratified_uniform();
      case SamplerKind::Halton:
        return halton_uniform();
    }
    return 0.f;
  }

  TESSERA_HOST_DEVICE Vec2 uniform2() {
    using namespace sobol_detail;
    switch (kind) {
      case SamplerKind::Independent:
        return rng.uniform2();
      case SamplerKind::Sobol:
        return sobol_uniform2();
      case SamplerKind::ZSobol: {
        const uint64_t key = dimension_hash();
        const uint64_t i = zsobol_detail::permuted_index(morton, index, log2_spp, key);
        return scrambled_dims01(static_cast<uint32_t>(i), mix_bits(key ^ (i >> (log2_spp + 6))));
      }
      case SamplerKind::Stratified:
        return stratified_uniform2();
      case SamplerKind::Halton:
        return halton_uniform2();
    }
    return Vec2(0.f);
  }

  // The point inside the pixel (the filter's sample): for Halton the
  // sequence's first two dimensions, whose leading digits chose the pixel
  // (pbrt-v4's GetPixel2D); for the other kinds the next 2D request.
  TESSERA_HOST_DEVICE Vec2 pixel2() {
    if (kind != SamplerKind::Halton) return uniform2();
    return Vec2(halton_detail::radical_inverse(2u, halton_index >> halton_exponent2),
                halton_detail::radical_inverse(3u, halton_index / halton_scale3));
  }

 private:
  // The kinds other than Independent and ZSobol (pbrt-v4's default): out of
  // line on the GPU (device.h), one copy each instead of one per request.
  TESSERA_HOST_DEVICE TESSERA_DEVICE_NOINLINE Float sobol_uniform() {
    using namespace sobol_detail;
    const uint64_t h = dimension_hash();
    return scrambled_dim0(nested_uniform_scramble(index, static_cast<uint32_t>(h)), static_cast<uint32_t>(h >> 32));
  }
  TESSERA_HOST_DEVICE TESSERA_DEVICE_NOINLINE Vec2 sobol_uniform2() {
    using namespace sobol_detail;
    const uint64_t h = dimension_hash();
    const uint64_t h2 = mix_bits(h);
    return scrambled_dims01(nested_uniform_scramble(index, static_cast<uint32_t>(h)), (h >> 32) | (h2 << 32));
  }
  TESSERA_HOST_DEVICE TESSERA_DEVICE_NOINLINE Float stratified_uniform() {
    const uint64_t key = dimension_hash();
    const uint32_t n = strata_x * strata_y;
    const uint32_t stratum = permutation_element(index, n, key);
    return glm::min((static_cast<Float>(stratum) + jitter_value(key, 0)) / static_cast<Float>(n), 0x1.fffffep-1f);
  }
  TESSERA_HOST_DEVICE TESSERA_DEVICE_NOINLINE Vec2 stratified_uniform2() {
    const uint64_t key = dimension_hash();
    const uint32_t stratum = permutation_element(index, strata_x * strata_y, key);
    const Float sx = static_cast<Float>(stratum % strata_x), sy = static_cast<Float>(stratum / strata_x);
    return Vec2(glm::min((sx + jitter_value(key, 0)) / static_cast<Float>(strata_x), 0x1.fffffep-1f),
                glm::min((sy + jitter_value(key, 1)) / static_cast<Float>(strata_y), 0x1.fffffep-1f));
  }
  TESSERA_HOST_DEVICE TESSERA_DEVICE_NOINLINE Float halton_uniform() {
    if (dimension >= halton_detail::kPrimeCount) dimension = 2;
    return halton_dimension(dimension++);
  }
  TESSERA_HOST_DEVICE TESSERA_DEVICE_NOINLINE Vec2 halton_uniform2() {
    if (dimension + 1 >= halton_detail::kPrimeCount) dimension = 2;
    const uint32_t d = dimension;
    dimension += 2;
    return Vec2(halton_dimension(d), halton_dimension(d + 1));
  }
  // The hash of this request's dimension (and epoch), then advances it.
  TESSERA_HOST_DEVICE uint64_t dimension_hash() {
    const uint64_t d = static_cast<uint64_t>(dimension++) | (static_cast<uint64_t>(epoch) << 32);
    return mix_bits(stream ^ (d * 0x9e3779b97f4a7c15ull));
  }
  // Halton: dimension d's randomised radical inverse, the same digit
  // permutations for every pixel (they randomise the one global sequence).
  TESSERA_HOST_DEVICE Float halton_dimension(uint32_t d) const {
    if (halton_randomize == HaltonRandomize::None) return halton_detail::radical_inverse(halton_detail::prime(d), halton_index);
    return halton_detail::scrambled_radical_inverse(halton_detail::prime(d), halton_index,
                                                    mix_bits(stream ^ (static_cast<uint64_t>(d) * 0x9e3779b97f4a7c15ull)),
                                                    halton_randomize == HaltonRandomize::Owen);
  }
  // Stratified: the jitter of coordinate c within the sample's stratum.
  TESSERA_HOST_DEVICE Float jitter_value(uint64_t key, uint32_t c) const {
    if (!jitter) return 0.5f;
    const uint64_t h = mix_bits(key ^ mix_bits((static_cast<uint64_t>(index) << 1 | c) + 0x632be59bd9b4e019ull));
    return static_cast<Float>(static_cast<uint32_t>(h >> 40)) * 0x1p-24f;
  }
};

}  // namespace tessera
