// Deterministic random numbers. Every stream is a pure function of
// (seed, pixel, sample index): the same image comes out whatever the thread,
// tile or rank that renders a pixel. Within a stream, dimensions are consumed
// in a fixed order by the integrator.
#pragma once

#include <cstring>

#include "device.h"

namespace tessera {

TESSERA_HOST_DEVICE inline uint64_t mix_bits(uint64_t v) {
  // splitmix64 finaliser: a cheap, well-distributed 64-bit hash.
  v ^= v >> 30;
  v *= 0xbf58476d1ce4e5b9ull;
  v ^= v >> 27;
  v *= 0x94d049bb133111ebull;
  v ^= v >> 31;
  return v;
}

// The bits of a float, without type punning (valid C++ and CUDA).
TESSERA_HOST_DEVICE inline uint32_t float_bits(Float f) {
  uint32_t u;
  memcpy(&u, &f, sizeof u);
  return u;
}

// A 64-bit hash of a point or direction in which every bit of all three
// coordinates counts (a direction and its mirror image hash differently).
TESSERA_HOST_DEVICE inline uint64_t hash_vec3(const Vec3& v) {
  return mix_bits(((static_cast<uint64_t>(float_bits(v.x)) << 32) | float_bits(v.y)) ^
                  mix_bits(float_bits(v.z) + 0x9e3779b97f4a7c15ull));
}

TESSERA_HOST_DEVICE inline uint64_t hash_stream(uint64_t seed, uint64_t pixel, uint64_t sample) {
  return mix_bits(mix_bits(mix_bits(seed + 0x9e3779b97f4a7c15ull) ^ pixel) ^ (sample * 0xd1b54a32d192ed03ull));
}

// PCG32 (O'Neill), the generator pbrt-v4 uses for its independent sampler.
struct Rng {
  uint64_t state = 0x853c49e6748fea9bull;
  uint64_t inc = 0xda3e39cb94b95bdbull;

  TESSERA_HOST_DEVICE static Rng for_sample(uint64_t seed, uint64_t pixel, uint64_t sample) {
    Rng r;
    r.set_sequence(hash_stream(seed, pixel, sample), mix_bits(pixel ^ (seed << 1)));
    return r;
  }
  TESSERA_HOST_DEVICE void set_sequence(uint64_t seq, uint64_t offset) {
    state = 0u;
    inc = (seq << 1u) | 1u;
    next_u32();
    state += offset;
    next_u32();
  }
  TESSERA_HOST_DEVICE uint32_t next_u32() {
    uint64_t old = state;
    state = old * 0x5851f42d4c957f2dull + inc;
    uint32_t xorshifted = static_cast<uint32_t>(((old >> 18u) ^ old) >> 27u);
    uint32_t rot = static_cast<uint32_t>(old >> 59u);
    return (xorshifted >> rot) | (xorshifted << ((~rot + 1u) & 31));
  }
  // Uniform in [0, 1): 24 random bits so the result is never rounded up to 1.
  TESSERA_HOST_DEVICE Float uniform() { return static_cast<Float>(next_u32() >> 8) * 0x1p-24f; }
  TESSERA_HOST_DEVICE Vec2 uniform2() {
    Float a = uniform();
    return Vec2(a, uniform());
  }
};

}  // namespace tessera
