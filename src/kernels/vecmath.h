// Small vector helpers shared by CPU and CUDA code.
#pragma once

#include <cmath>

#include "device.h"

namespace tessera {

// |x| is fabsf throughout the kernels, never glm::abs: glm's `x >= 0 ? x : -x`
// must keep the sign of -0 and NaN, so g++ cannot turn it into a mask and
// branches instead; on random signs (direction components) the mispredictions
// cost ~5 % of a guided render. fabsf is one and-not on the CPU and on CUDA.
TESSERA_HOST_DEVICE inline Vec3 abs3(const Vec3& v) { return Vec3(fabsf(v.x), fabsf(v.y), fabsf(v.z)); }

// The unit normal cross(a - c, b - c) / |...| of triangle (a, b, c) and its
// area, false for a degenerate one. In double: the cross product of a
// triangle 1e10 across (4e20) squares past float's range in the length.
TESSERA_HOST_DEVICE inline bool triangle_normal(const Vec3& a, const Vec3& b, const Vec3& c, Vec3* n, double* area) {
  const glm::dvec3 nd = glm::cross(glm::dvec3(a) - glm::dvec3(c), glm::dvec3(b) - glm::dvec3(c));
  const double len = glm::length(nd);
  if (!(len > 0.0)) return false;
  *n = Vec3(nd / len);
  if (area) *area = 0.5 * len;
  return true;
}

TESSERA_HOST_DEVICE inline Float max_component(const Vec3& v) { return glm::max(v.x, glm::max(v.y, v.z)); }
TESSERA_HOST_DEVICE inline Float luminance(const Rgb& c) { return 0.2126f * c.x + 0.7152f * c.y + 0.0722f * c.z; }
TESSERA_HOST_DEVICE inline bool is_black(const Rgb& c) { return c.x == 0.f && c.y == 0.f && c.z == 0.f; }
TESSERA_HOST_DEVICE inline bool is_finite(const Vec3& v) {
  return fabsf(v.x) <= 3.4e38f && fabsf(v.y) <= 3.4e38f && fabsf(v.z) <= 3.4e38f;  // false for NaN too
}
TESSERA_HOST_DEVICE inline Float safe_sqrt(Float x) { return glm::sqrt(glm::max(x, 0.f)); }
TESSERA_HOST_DEVICE inline Float sqr(Float x) { return x * x; }

// Orthonormal basis around a unit normal (Duff et al. 2017, branchless).
struct Frame {
  Vec3 s, t, n;

  TESSERA_HOST_DEVICE static Frame from_z(const Vec3& n) {
    Float sign = glm::sign(n.z) + (n.z == 0.f ? 1.f : 0.f);
    Float a = -1.f / (sign + n.z);
    Float b = n.x * n.y * a;
    Frame f;
    f.s = Vec3(1.f + sign * n.x * n.x * a, sign * b, -sign * n.x);
    f.t = Vec3(b, sign + n.y * n.y * a, -n.y);
    f.n = n;
    return f;
  }
  // x along the tangent (made orthogonal to n), z = n: pbrt-v4's Frame::FromXZ.
  TESSERA_HOST_DEVICE static Frame from_tangent(const Vec3& n, const Vec3& tangent) {
    Vec3 s = tangent - n * glm::dot(n, tangent);
    Float len = glm::length(s);
    if (!(len > 1e-12f)) return from_z(n);
    Frame f;
    f.n = n;
    f.s = s / len;
    f.t = glm::cross(n, f.s);
    return f;
  }
  TESSERA_HOST_DEVICE TESSERA_INLINE Vec3 to_local(const Vec3& v) const { return Vec3(glm::dot(v, s), glm::dot(v, t), glm::dot(v, n)); }
  TESSERA_HOST_DEVICE TESSERA_INLINE Vec3 to_world(const Vec3& v) const { return s * v.x + t * v.y + n * v.z; }
};

// Local shading-frame trigonometry (z is the normal), as in pbrt.
TESSERA_HOST_DEVICE inline Float cos_theta(const Vec3& w) { return w.z; }
TESSERA_HOST_DEVICE inline Float abs_cos_theta(const Vec3& w) { return fabsf(w.z); }
TESSERA_HOST_DEVICE inline Float cos2_theta(const Vec3& w) { return w.z * w.z; }
TESSERA_HOST_DEVICE inline Float sin2_theta(const Vec3& w) { return glm::max(0.f, 1.f - cos2_theta(w)); }
TESSERA_HOST_DEVICE inline Float tan2_theta(const Vec3& w) { return sin2_theta(w) / cos2_theta(w); }
TESSERA_HOST_DEVICE inline bool same_hemisphere(const Vec3& a, const Vec3& b) { return a.z * b.z > 0.f; }

TESSERA_HOST_DEVICE inline Vec3 reflect(const Vec3& wo, const Vec3& n) { return -wo + 2.f * glm::dot(wo, n) * n; }

// Refraction of wi about n (n on wi's side) with relative IOR eta = n_t / n_i.
// Returns false on total internal reflection. pbrt-v4 semantics.
TESSERA_HOST_DEVICE inline bool refract(const Vec3& wi, Vec3 n, Float eta, Float* etap, Vec3* wt) {
  Float cos_i = glm::dot(n, wi);
  if (cos_i < 0.f) {
    eta = 1.f / eta;
    cos_i = -cos_i;
    n = -n;
  }
  Float sin2_i = glm::max(0.f, 1.f - cos_i * cos_i);
  Float sin2_t = sin2_i / (eta * eta);
  if (sin2_t >= 1.f) return false;
  Float cos_t = safe_sqrt(1.f - sin2_t);
  *wt = -wi / eta + (cos_i / eta - cos_t) * n;
  if (etap) *etap = eta;
  return true;
}

}  // namespace tessera
