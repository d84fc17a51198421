// Clarberg's equal-area mapping between the unit square and the sphere
// (octahedral layout), as pbrt-v4 uses for environment maps. Because the map
// preserves area, a density p(u,v) on the square is p / (4 pi) per steradian.
#pragma once

#include <cmath>

#include "vecmath.h"

namespace tessera {

TESSERA_HOST_DEVICE inline Vec3 equal_area_square_to_sphere(Vec2 p) {
  Float u = 2.f * p.x - 1.f, v = 2.f * p.y - 1.f;
  Float up = fabsf(u), vp = fabsf(v);
  Float signed_distance = 1.f - (up + vp);
  Float d = fabsf(signed_distance);
  Float r = 1.f - d;
  // phi = pi/4 + x with x in [-pi/4, pi/4]: short Taylor series of x give
  // sin and cos within 3e-8 (the mapped direction stays within 2.4e-7 of a
  // double-precision map), with no libm call on the guiding hot path
  // (sincosf was 4 % of a guided render) and the same numbers on CPU and GPU.
  const Float x = r == 0.f ? 0.f : (vp - up) / r * (kPi / 4.f);
  const Float x2 = x * x;
  const Float sin_x = x + x * x2 * (-1.f / 6.f + x2 * (1.f / 120.f + x2 * (-1.f / 5040.f + x2 * (1.f / 362880.f))));
  const Float cos_x = 1.f + x2 * (-0.5f + x2 * (1.f / 24.f + x2 * (-1.f / 720.f + x2 * (1.f / 40320.f))));
  constexpr Float kInvSqrt2 = 0.70710678118654752f;
  const Float cos_p = (cos_x - sin_x) * kInvSqrt2;  // cos(pi/4 + x)
  const Float sin_p = (cos_x + sin_x) * kInvSqrt2;  // sin(pi/4 + x)
  Float z = glm::sign(signed_distance) * (1.f - r * r);
  if (signed_distance == 0.f) z = 0.f;
  Float cos_phi = fabsf(cos_p) * (u < 0.f ? -1.f : 1.f);
  Float sin_phi = fabsf(sin_p) * (v < 0.f ? -1.f : 1.f);
  Float s = r * safe_sqrt(2.f - r * r);
  return Vec3(cos_phi * s, sin_phi * s, z);
}

TESSERA_HOST_DEVICE inline Vec2 equal_area_sphere_to_square(Vec3 d) {
  Float x = fabsf(d.x), y = fabsf(d.y), z = fabsf(d.z);
  Float r = safe_sqrt(1.f - z);
  Float a = glm::max(x, y), b = glm::min(x, y);
  b = a == 0.f ? 0.f : b / a;
  // atan(b) * 2/pi for b in [0,1]: pbrt-v4's 6th-degree minimax polynomial
  // (what pbrt itself evaluates, and no libm call on the guiding hot path),
  // in Estrin's form: independent pairs instead of one chain of six
  // multiply-adds, about half the latency on the guide's hot path.
  const Float b2 = b * b;
  const Float c01 = 0.406758566246788489601959989e-5f + b * 0.636226545274016134946890922156f;
  const Float c23 = 0.61572017898280213493197203466e-2f + b * -0.247333733281268944196501420480f;
  const Float c45 = 0.881770664775316294736387951347e-1f + b * 0.419038818029165735901852432784e-1f;
  const Float c6 = -0.251390972343483509333252996350e-1f;
  const Float b4 = b2 * b2;
  Float phi = (c01 + b2 * c23) + b4 * (c45 + b2 * c6);
  if (x < y) phi = 1.f - phi;
  Float v = phi * r;
  Float u = r - v;
  if (d.z < 0.f) {
    Float t = u;
    u = 1.f - v;
    v = 1.f - t;
  }
  u = d.x < 0.f ? -u : u;
  v = d.y < 0.f ? -v : v;
  return Vec2(0.5f * (u + 1.f), 0.5f * (v + 1.f));
}

}  // namespace tessera
