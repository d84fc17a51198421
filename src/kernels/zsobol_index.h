// Sample indices of the z-ordered Sobol sampler (pbrt-v4's "zsobol", after
// Ahmed & Wonka 2020, "Screen-Space Blue-Noise Diffusion of Monte Carlo
// Sampling Error via Hierarchical Ordering of Pixels").
//
// All pixels draw from one Sobol sequence: pixel (x, y)'s samples are the
// indices (morton(x, y) << L) | s, s < 2^L, so that neighbouring pixels hold
// neighbouring blocks of the sequence and their errors are spread like blue
// noise. Every base-4 digit of that index (two bits: one level of the
// Morton quadtree) is then permuted, by a permutation chosen by a hash of
// the digits above it and of the dimension: a random relabelling of the
// quadtree that decorrelates the dimensions and keeps every aligned block of
// indices aligned. Pixel digits take any of the 24 permutations of
// {0,1,2,3}; sample digits only the 8 that keep their two bits' nesting
// (binary Owen scrambling of the pair), so that a pixel's first 2^k samples
// stay a (0,k,2)-net for every k <= L, odd k included (passes are 8 spp).
//
// The points are then Owen-scrambled per request, with one scramble for
// each aligned 8 x 8 block of pixels (sampler.h), so the net property holds
// within such blocks.
//
// Past 2^L samples (a --time render longer than the scene's pixelsamples)
// a pixel does not run into its neighbour's indices: each further block of
// 2^L samples (an "epoch") is the same construction under fresh hashes.
#pragma once

#include "rng.h"

namespace tessera {
namespace zsobol_detail {

// Pixel coordinates up to 2^16 per side: 16 base-4 digits of Morton code.
constexpr uint32_t kPixelLevels = 16;

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

// Digit d (0..3) under permutation p (0..23) of {0,1,2,3}, p read as a
// Lehmer code (factorial number system): its digits pick, in turn, one of
// the elements not yet used.
TESSERA_HOST_DEVICE inline uint32_t permute_digit(uint32_t p, uint32_t d) {
  uint32_t unused = 0x3210u;  // nibbles: the elements not yet placed, in order
  uint32_t out = 0;
  const uint32_t radix[4] = {6u, 2u, 1u, 1u};
  for (uint32_t pos = 0; pos <= d; ++pos) {
    const uint32_t pick = (p / radix[pos]) % (4u - pos);
    out = (unused >> (4u * pick)) & 0xfu;
    // Remove the picked nibble.
    const uint32_t low = unused & ((1u << (4u * pick)) - 1u);
    unused = ((unused >> (4u * (pick + 1u))) << (4u * pick)) | low;
  }
  return out;
}

// The permuted index of sample s of the pixel with Morton code m, for one
// dimension, with L = log2 of the samples per epoch and `key` a hash of
// (seed, dimension, epoch).
TESSERA_HOST_DEVICE inline uint64_t permuted_index(uint64_t m, uint32_t s, uint32_t L, uint64_t key) {
  const uint64_t index = (m << L) | (L == 0 ? 0ull : (static_cast<uint64_t>(s) & ((1ull << L) - 1ull)));
  const uint32_t odd = L & 1u;
  const uint32_t digits = kPixelLevels + L / 2u;
  uint64_t out = 0;
  for (uint32_t i = digits; i-- > 0;) {
    const uint32_t shift = 2u * i + odd;
    const uint32_t digit = static_cast<uint32_t>(index >> shift) & 3u;
    const uint64_t higher = shift + 2u < 64u ? index >> (shift + 2u) : 0ull;
    const uint64_t r = mix_bits(higher ^ key ^ (static_cast<uint64_t>(i) << 58));
    uint32_t permuted;
    if (shift >= L) {
      permuted = permute_digit(static_cast<uint32_t>((r >> 24) % 24u), digit);
    } else {
      const uint32_t hi = digit >> 1, lo = digit & 1u;
      permuted = ((hi ^ static_cast<uint32_t>(r & 1u)) << 1) | (lo ^ static_cast<uint32_t>((r >> (1u + hi)) & 1u));
    }
    out |= static_cast<uint64_t>(permuted) << shift;
  }
  if (odd) out |= (index & 1ull) ^ (mix_bits((index >> 1) ^ key) & 1ull);
  return out;
}

}  // namespace zsobol_detail
}  // namespace tessera
