// Gradient noise as pbrt-v4 defines it for its procedural media and
// textures: Ken Perlin's improved noise ("Improving Noise", SIGGRAPH 2002)
// with his reference permutation and quintic fade, and pbrt-v4's choice of
// gradient for each hash (which differs from Perlin's for hashes 12-15), so
// that a cloud reads the same numbers as pbrt-v4 at the same point.
#pragma once

#include "device.h"
#include "vecmath.h"

namespace tessera {

// Perlin's reference permutation of 0..255, repeated once so that hashes
// of a lattice point's neighbours never wrap.
#define TESSERA_PERLIN_PERMUTATION                                                                                   \
  151, 160, 137, 91, 90, 15, 131, 13, 201, 95, 96, 53, 194, 233, 7, 225, 140, 36, 103, 30, 69, 142, 8, 99, 37, 240,   \
      21, 10, 23, 190, 6, 148, 247, 120, 234, 75, 0, 26, 197, 62, 94, 252, 219, 203, 117, 35, 11, 32, 57, 177, 33, 88, \
      237, 149, 56, 87, 174, 20, 125, 136, 171, 168, 68, 175, 74, 165, 71, 134, 139, 48, 27, 166, 77, 146, 158, 231,   \
      83, 111, 229, 122, 60, 211, 133, 230, 220, 105, 92, 41, 55, 46, 245, 40, 244, 102, 143, 54, 65, 25, 63, 161, 1,  \
      216, 80, 73, 209, 76, 132, 187, 208, 89, 18, 169, 200, 196, 135, 130, 116, 188, 159, 86, 164, 100, 109, 198,     \
      173, 186, 3, 64, 52, 217, 226, 250, 124, 123, 5, 202, 38, 147, 118, 126, 255, 82, 85, 212, 207, 206, 59, 227,    \
      47, 16, 58, 17, 182, 189, 28, 42, 223, 183, 170, 213, 119, 248, 152, 2, 44, 154, 163, 70, 221, 153, 101, 155,    \
      167, 43, 172, 9, 129, 22, 39, 253, 19, 98, 108, 110, 79, 113, 224, 232, 178, 185, 112, 104, 218, 246, 97, 228,   \
      251, 34, 242, 193, 238, 210, 144, 12, 191, 179, 162, 241, 81, 51, 145, 235, 249, 14, 239, 107, 49, 192, 214, 31, \
      181, 199, 106, 157, 184, 84, 204, 176, 115, 121, 50, 45, 127, 4, 150, 254, 138, 236, 205, 93, 222, 114, 67, 29,  \
      24, 72, 243, 141, 128, 195, 78, 66, 215, 61, 156, 180

#if defined(__CUDACC__)
static __constant__ uint8_t kPerlinPermutationDevice[256] = {TESSERA_PERLIN_PERMUTATION};
#endif
inline constexpr uint8_t kPerlinPermutationHost[256] = {TESSERA_PERLIN_PERMUTATION};
#undef TESSERA_PERLIN_PERMUTATION

TESSERA_HOST_DEVICE inline int32_t perlin_permutation(int32_t i) {
#if TESSERA_IS_GPU_CODE
  return kPerlinPermutationDevice[i & 255];
#else
  return kPerlinPermutationHost[i & 255];
#endif
}

// The dot product of the lattice point's gradient with the offset d.
TESSERA_HOST_DEVICE inline Float perlin_gradient(int32_t x, int32_t y, int32_t z, Float dx, Float dy, Float dz) {
  const int32_t h = perlin_permutation(perlin_permutation(perlin_permutation(x) + y) + z) & 15;
  const Float u = h < 8 || h == 12 || h == 13 ? dx : dy;
  const Float v = h < 4 || h == 12 || h == 13 ? dy : dz;
  return ((h & 1) ? -u : u) + ((h & 2) ? -v : v);
}

TESSERA_HOST_DEVICE inline Float perlin_fade(Float t) { return t * t * t * (t * (t * 6.f - 15.f) + 10.f); }

// Noise at p: 0 at the integer lattice, within about [-1, 1]. The lattice
// repeats every 256 units; coordinates beyond +-2^24 (no fraction left in
// float) and NaN read 0.
TESSERA_HOST_DEVICE inline Float perlin_noise(Vec3 p) {
  constexpr Float kLimit = 16777216.f;
  if (!(glm::abs(p.x) < kLimit && glm::abs(p.y) < kLimit && glm::abs(p.z) < kLimit)) return 0.f;
  const Float fx = glm::floor(p.x), fy = glm::floor(p.y), fz = glm::floor(p.z);
  const Float dx = p.x - fx, dy = p.y - fy, dz = p.z - fz;
  const int32_t x = static_cast<int32_t>(fx) & 255, y = static_cast<int32_t>(fy) & 255, z = static_cast<int32_t>(fz) & 255;
  const Float wx = perlin_fade(dx), wy = perlin_fade(dy), wz = perlin_fade(dz);
  auto lerp = [](Float t, Float a, Float b) { return (1.f - t) * a + t * b; };
  const Float x00 = lerp(wx, perlin_gradient(x, y, z, dx, dy, dz), perlin_gradient(x + 1, y, z, dx - 1.f, dy, dz));
  const Float x10 =
      lerp(wx, perlin_gradient(x, y + 1, z, dx, dy - 1.f, dz), perlin_gradient(x + 1, y + 1, z, dx - 1.f, dy - 1.f, dz));
  const Float x01 =
      lerp(wx, perlin_gradient(x, y, z + 1, dx, dy, dz - 1.f), perlin_gradient(x + 1, y, z + 1, dx - 1.f, dy, dz - 1.f));
  const Float x11 = lerp(wx, perlin_gradient(x, y + 1, z + 1, dx, dy - 1.f, dz - 1.f),
                         perlin_gradient(x + 1, y + 1, z + 1, dx - 1.f, dy - 1.f, dz - 1.f));
  return lerp(wz, lerp(wy, x00, x10), lerp(wy, x01, x11));
}

// pbrt-v4's DNoise: the noise's forward-difference gradient, step 0.01.
TESSERA_HOST_DEVICE inline Vec3 perlin_noise_gradient(const Vec3& p) {
  constexpr Float kDelta = 0.01f;
  const Float n = perlin_noise(p);
  return Vec3(perlin_noise(p + Vec3(kDelta, 0.f, 0.f)) - n, perlin_noise(p + Vec3(0.f, kDelta, 0.f)) - n,
              perlin_noise(p + Vec3(0.f, 0.f, kDelta)) - n) /
         kDelta;
}

// pbrt-v4's FBm and Turbulence: octaves of noise at frequencies 1, 1.99,
// 1.99^2, ... weighted 1, omega, omega^2, ... (turbulence sums |noise|).
// pbrt-v4 drops the octaves finer than the ray differentials' footprint;
// without ray differentials every one of max_octaves is summed, which is
// pbrt-v4's value for a footprint of zero (turbulence then adds its
// stand-in for the first dropped octave, 0.2 times its weight, as pbrt-v4 does).
TESSERA_HOST_DEVICE inline Float fbm_noise(const Vec3& p, Float omega, int32_t max_octaves) {
  Float sum = 0.f, lambda = 1.f, o = 1.f;
  for (int32_t i = 0; i < max_octaves; ++i) {
    sum += o * perlin_noise(lambda * p);
    lambda *= 1.99f;
    o *= omega;
  }
  return sum;
}

TESSERA_HOST_DEVICE inline Float turbulence_noise(const Vec3& p, Float omega, int32_t max_octaves) {
  Float sum = 0.f, lambda = 1.f, o = 1.f;
  for (int32_t i = 0; i < max_octaves; ++i) {
    sum += o * glm::abs(perlin_noise(lambda * p));
    lambda *= 1.99f;
    o *= omega;
  }
  return sum + o * 0.2f;
}

}  // namespace tessera
