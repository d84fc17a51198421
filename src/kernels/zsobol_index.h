// Sample indices of the z-ordered Sobol sampler (pbrt-v4's "zsobol", after
// Ahmed & Wonka 2020, "Screen-Space Blue-Noise Diffusion of Monte Carlo
// Sampling Error via Hierarchical Ordering of Pixels").
//
// All pixels draw from one Sobol sequence: pixel (x, y)'s samples are the
// indices (morton(x, y) << L) | s, s < 2^L, so that neighbouring pixels hold
// neighbouring blocks of the sequence and their errors are spread like blue
// noise. The index is then Owen-scrambled as a whole, per request: every bit
// flipped by a hash of the bits above it. That relabels the Morton
// quadtree's children at every level (pbrt-v4 draws each level's relabelling
// from all 24 permutations of four children; binary scrambling from the 8
// that keep the two bits nested) and keeps every aligned block of indices
// aligned, so a pixel's first 2^k samples stay a (0,k,2)-net for every
// k <= L, and so do the samples of an aligned block of pixels. One hash per
// request: per-level hashing cost as much as the rest of a path.
//
// The points are then Owen-scrambled per request, with one scramble for
// each aligned 8 x 8 block of pixels (sampler.h), so the net property holds
// within such blocks.
//
// Past 2^L samples (a --time render longer than the scene's pixelsamples)
// a pixel does not run into its neighbour's indices: each further block of
// 2^L samples (an "epoch") is the same construction under fresh hashes.
#pragma once

#include "sobol_points.h"

namespace tessera {
namespace zsobol_detail {

// Interleaves the bits of x (even positions) and y (odd positions).
TESSERA_HOST_DEVICE inline uint64_t morton2(uint32_t x, uint32_t y) {
  auto spread = [](uint64_t v) {
    v &= 0xffffffffull;
    v = (v | (v << 16)) & 0x0000ffff0000ffffull;
    v = (v | (v << 8)) & 0x00ff00ff00ff00ffull;
    v = (v | (v << 4)) & 0x0f0f0f0f0f0f0f0full;
    v = (v | (v << 2)) & 0x3333333333333333ull;
    v = (v | (v << 1)) & 0x5555555555555555ull;
    return v;
  };
  return spread(x) | (spread(y) << 1);
}

TESSERA_HOST_DEVICE inline uint64_t reverse_bits64(uint64_t v) {
  return (static_cast<uint64_t>(sobol_detail::reverse_bits(static_cast<uint32_t>(v))) << 32) |
         sobol_detail::reverse_bits(static_cast<uint32_t>(v >> 32));
}

// Owen scrambling of a 64-bit index: bit k flipped by a hash of the bits
// above it (Burley's Laine-Karras construction on the reversed bits: each
// step only lets a bit affect higher ones).
TESSERA_HOST_DEVICE inline uint64_t nested_scramble64(uint64_t index, uint64_t seed) {
  uint64_t x = reverse_bits64(index);
  x ^= x * 0x3d20adea2e0c5b1aull;
  x += seed;
  x *= (seed >> 32) | 1ull;
  x ^= x * 0x05526c56a1e0f2c4ull;
  x ^= x * 0x53a22864bc9e3d16ull;
  return reverse_bits64(x);
}

// The scrambled index of sample s of the pixel with Morton code m, with
// L = log2 of the samples per epoch and `key` a hash of (seed, request, epoch).
TESSERA_HOST_DEVICE inline uint64_t permuted_index(uint64_t m, uint32_t s, uint32_t L, uint64_t key) {
  const uint64_t index = (m << L) | (L == 0 ? 0ull : (static_cast<uint64_t>(s) & ((1ull << L) - 1ull)));
  return nested_scramble64(index, key);
}

}  // namespace zsobol_detail
}  // namespace tessera
