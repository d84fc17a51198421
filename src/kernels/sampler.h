// The random numbers of one pixel sample, drawn dimension by dimension: a pure
// function of (seed, pixel, sample index, dimension), so that any thread or
// rank renders the same image.
//
// Two kinds, chosen by pbrt-v4's Sampler directive:
// * Independent: PCG32 (pbrt-v4's IndependentSampler).
// * Sobol: every 1D and 2D request is the next point of the first two Sobol
//   dimensions (a (0,2)-sequence) with Burley's (2020) hash-based Owen
//   scrambling, and the sample index itself Owen-shuffled, both with seeds
//   hashed from (seed, pixel, dimension) - pbrt-v4's padded Sobol with
//   FastOwen randomisation. Every power-of-two prefix of a pixel's samples is
//   stratified in each 1D and 2D request, for any sample count, so passes of
//   any length keep the stratification of the whole.
#pragma once

#include "rng.h"

namespace tessera {

enum class SamplerKind : uint32_t { Independent = 0, Sobol = 1 };

namespace sobol_detail {

TESSERA_HOST_DEVICE inline uint32_t reverse_bits(uint32_t v) {
  v = ((v >> 1) & 0x55555555u) | ((v & 0x55555555u) << 1);
  v = ((v >> 2) & 0x33333333u) | ((v & 0x33333333u) << 2);
  v = ((v >> 4) & 0x0f0f0f0fu) | ((v & 0x0f0f0f0fu) << 4);
  v = ((v >> 8) & 0x00ff00ffu) | ((v & 0x00ff00ffu) << 8);
  return (v >> 16) | (v << 16);
}

// Laine-Karras style permutation of the bits above each bit (Burley 2020).
TESSERA_HOST_DEVICE inline uint32_t laine_karras(uint32_t x, uint32_t seed) {
  x ^= x * 0x3d20adeau;
  x += seed;
  x *= (seed >> 16) | 1u;
  x ^= x * 0x05526c56u;
  x ^= x * 0x53a22864u;
  return x;
}

// Owen scrambling of a value whose bits are read from the most significant.
TESSERA_HOST_DEVICE inline uint32_t nested_uniform_scramble(uint32_t x, uint32_t seed) {
  return reverse_bits(laine_karras(reverse_bits(x), seed));
}

// The second Sobol dimension: the generator matrix of the primitive
// polynomial x + 1 (direction numbers m_k = m_{k-1} xor 2 m_{k-1}, m_1 = 1).
TESSERA_HOST_DEVICE inline uint32_t sobol_dim1(uint32_t index) {
  uint32_t v = 0, direction = 0x80000000u;
  for (; index != 0; index >>= 1, direction ^= direction >> 1)
    if (index & 1u) v ^= direction;
  return v;
}

TESSERA_HOST_DEVICE inline Float to_unit(uint32_t v) {
  return glm::min(static_cast<Float>(v >> 8) * 0x1p-24f, 0x1.fffffep-1f);
}

}  // namespace sobol_detail

struct PixelSampler {
  SamplerKind kind = SamplerKind::Independent;
  Rng rng;               // Independent
  uint64_t stream = 0;   // Sobol: hash of (seed, pixel)
  uint32_t index = 0;    // Sobol: sample index within the pixel
  uint32_t dimension = 0;

  TESSERA_HOST_DEVICE static PixelSampler start(SamplerKind kind, uint64_t seed, uint64_t pixel, uint64_t sample) {
    PixelSampler s;
    s.kind = kind;
    if (kind == SamplerKind::Independent) {
      s.rng = Rng::for_sample(seed, pixel, sample);
    } else {
      s.stream = hash_stream(seed, pixel, 0x50b01ull);
      s.index = static_cast<uint32_t>(sample);
    }
    return s;
  }

  TESSERA_HOST_DEVICE Float uniform() {
    if (kind == SamplerKind::Independent) return rng.uniform();
    using namespace sobol_detail;
    const uint64_t h = mix_bits(stream ^ (static_cast<uint64_t>(dimension++) * 0x9e3779b97f4a7c15ull));
    const uint32_t i = nested_uniform_scramble(index, static_cast<uint32_t>(h));
    return to_unit(nested_uniform_scramble(reverse_bits(i), static_cast<uint32_t>(h >> 32)));
  }

  TESSERA_HOST_DEVICE Vec2 uniform2() {
    if (kind == SamplerKind::Independent) return rng.uniform2();
    using namespace sobol_detail;
    const uint64_t h = mix_bits(stream ^ (static_cast<uint64_t>(dimension++) * 0x9e3779b97f4a7c15ull));
    const uint64_t h2 = mix_bits(h);
    const uint32_t i = nested_uniform_scramble(index, static_cast<uint32_t>(h));
    return Vec2(to_unit(nested_uniform_scramble(reverse_bits(i), static_cast<uint32_t>(h >> 32))),
                to_unit(nested_uniform_scramble(sobol_dim1(i), static_cast<uint32_t>(h2))));
  }
};

}  // namespace tessera
