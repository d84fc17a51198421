// The first two dimensions of the Sobol sequence and Owen scrambling: the
// building blocks of the low-discrepancy samplers (sampler.h).
//
// Dimension 0 is the van der Corput sequence (the index's bits reversed),
// dimension 1 the generator of the primitive polynomial x + 1; together they
// are a (0,2)-sequence: every aligned block of 2^k consecutive indices is a
// (0,k,2)-net. Scrambling is Burley's (2020) hash-based Owen scrambling.
#pragma once

#include "rng.h"

namespace tessera {
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
// polynomial x + 1 (direction numbers m_k = m_{k-1} xor 2 m_{k-1}, m_1 = 1),
// which is Pascal's triangle mod 2. By Lucas' theorem the output bit p
// places below the top is the xor of the index bits j with p & j == p: a
// xor "superset sum" over 5-bit positions, five shift-and-mask steps
// instead of a loop over the index's 32 bits.
// sobol_dim1 with its bits reversed (least significant = the top bit of the point).
TESSERA_HOST_DEVICE inline uint32_t sobol_dim1_reversed(uint32_t index) {
  uint32_t x = index;
  x ^= (x >> 1) & 0x55555555u;
  x ^= (x >> 2) & 0x33333333u;
  x ^= (x >> 4) & 0x0f0f0f0fu;
  x ^= (x >> 8) & 0x00ff00ffu;
  x ^= (x >> 16) & 0x0000ffffu;
  return x;
}
TESSERA_HOST_DEVICE inline uint32_t sobol_dim1(uint32_t index) { return reverse_bits(sobol_dim1_reversed(index)); }

TESSERA_HOST_DEVICE inline Float to_unit(uint32_t v) {
  return glm::min(static_cast<Float>(v >> 8) * 0x1p-24f, 0x1.fffffep-1f);
}

// Owen-scrambled points of dimension 0, and of dimensions 0 and 1, of index
// i. Scrambling a point reverses its bits, hashes and reverses back; the
// points are themselves reversed forms (dimension 0 is reverse_bits(i)), so
// two of the four reversals cancel.
TESSERA_HOST_DEVICE inline Float scrambled_dim0(uint32_t i, uint32_t seed) {
  return to_unit(reverse_bits(laine_karras(i, seed)));
}
TESSERA_HOST_DEVICE inline Vec2 scrambled_dims01(uint32_t i, uint64_t seeds) {
  return Vec2(to_unit(reverse_bits(laine_karras(i, static_cast<uint32_t>(seeds)))),
              to_unit(reverse_bits(laine_karras(sobol_dim1_reversed(i), static_cast<uint32_t>(seeds >> 32)))));
}

}  // namespace sobol_detail
}  // namespace tessera
