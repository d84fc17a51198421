// Directions towards a triangle drawn uniformly in the solid angle it
// subtends (Arvo, "Stratified sampling of spherical triangles", 1995), as
// pbrt-v4 samples triangle lights that look large from the shading point.
// Sampling by area instead gives a light sample's weight A cos / d^2, which
// grows without bound near the light: uniform solid-angle samples weigh the
// solid angle, at most 2 pi. Used for light samples taken in media (a fog
// around a lamp); on surfaces the receiver's cosine already tames the area
// sample's weight, and solid-angle sampling cost more time than it saved in
// error (cornell-box).
#pragma once

#include "vecmath.h"

namespace tessera {

// The range sampled by solid angle. pbrt-v4 starts at 3e-4 sr, where the
// spherical formulas still keep their precision in float; we start where
// area sampling's weights begin to vary much over the triangle: from 3e-4
// the extra arithmetic made media scenes a third slower (cornell-box-volume
// 10.7 -> 14.4 s) for the same error gain that 0.05 gives at 3 % more time.
// Above the top the triangle nearly fills a hemisphere.
constexpr Float kMinSphericalSampleSolidAngle = 0.05f;
constexpr Float kMaxSphericalSampleSolidAngle = 6.22f;

// Solid angle of triangle (v0, v1, v2) seen from p (Van Oosterom and
// Strackee's formula on the unit vectors towards the vertices).
TESSERA_HOST_DEVICE inline Float triangle_solid_angle(const Vec3& p, const Vec3& v0, const Vec3& v1, const Vec3& v2) {
  const Vec3 a = glm::normalize(v0 - p), b = glm::normalize(v1 - p), c = glm::normalize(v2 - p);
  const Float num = glm::abs(glm::dot(a, glm::cross(b, c)));
  const Float den = 1.f + glm::dot(a, b) + glm::dot(b, c) + glm::dot(c, a);
  const Float omega = 2.f * glm::atan(num, den);
  return omega > 0.f && omega < kInfinity ? omega : 0.f;
}

// Whether a triangle of this solid angle is sampled by solid angle.
TESSERA_HOST_DEVICE inline bool samples_by_solid_angle(Float omega) {
  return omega >= kMinSphericalSampleSolidAngle && omega <= kMaxSphericalSampleSolidAngle;
}

// The component of v orthogonal to unit vector n, normalised.
TESSERA_HOST_DEVICE inline Vec3 orthonormal_part(const Vec3& v, const Vec3& n) {
  return glm::normalize(v - glm::dot(v, n) * n);
}

// Arvo's method: pick the sub-triangle (A, B, C') whose area is u.x times
// the whole, then a point on the arc from B to C' so that the area swept is
// uniform in u.y. Returns the unit direction from p; false when the
// triangle is degenerate as seen from p.
TESSERA_HOST_DEVICE inline bool sample_spherical_triangle(const Vec3& p, const Vec3& v0, const Vec3& v1,
                                                          const Vec3& v2, Vec2 u, Vec3* w) {
  const Vec3 a = glm::normalize(v0 - p), b = glm::normalize(v1 - p), c = glm::normalize(v2 - p);
  Vec3 n_ab = glm::cross(a, b), n_bc = glm::cross(b, c), n_ca = glm::cross(c, a);
  if (!(glm::dot(n_ab, n_ab) > 0.f) || !(glm::dot(n_bc, n_bc) > 0.f) || !(glm::dot(n_ca, n_ca) > 0.f)) return false;
  n_ab = glm::normalize(n_ab);
  n_bc = glm::normalize(n_bc);
  n_ca = glm::normalize(n_ca);
  // Interior angles: between the great circles meeting at each vertex. From
  // the half chord (asin), which keeps its precision near 0 and pi where
  // acos of the dot product does not (thin triangles have such angles).
  auto angle = [](const Vec3& x, const Vec3& y) {
    if (glm::dot(x, y) < 0.f) return kPi - 2.f * glm::asin(glm::min(1.f, 0.5f * glm::length(x + y)));
    return 2.f * glm::asin(glm::min(1.f, 0.5f * glm::length(y - x)));
  };
  const Float alpha = angle(n_ab, -n_ca), beta = angle(n_bc, -n_ab), gamma = angle(n_ca, -n_bc);
  const Float area = alpha + beta + gamma - kPi;
  if (!(area > 0.f)) return false;
  // The sub-triangle's area, and the cosine of its edge from A to C'.
  const Float sub = u.x * area;
  const Float s = glm::sin(sub - alpha), t = glm::cos(sub - alpha);
  const Float cos_alpha = glm::cos(alpha), sin_alpha = glm::sin(alpha);
  const Float uu = t - cos_alpha;
  const Float vv = s + sin_alpha * glm::dot(a, b);
  const Float den = (vv * s + uu * t) * sin_alpha;
  if (!(glm::abs(den) > 0.f)) return false;
  const Float q = glm::clamp(((vv * t - uu * s) * cos_alpha - vv) / den, -1.f, 1.f);
  const Vec3 c_sub = q * a + glm::sqrt(glm::max(0.f, 1.f - q * q)) * orthonormal_part(c, a);
  // Uniform in the area swept along the arc from B towards C'.
  const Float z = 1.f - u.y * (1.f - glm::dot(c_sub, b));
  const Vec3 dir = z * b + glm::sqrt(glm::max(0.f, 1.f - z * z)) * orthonormal_part(c_sub, b);
  const Float len = glm::length(dir);
  if (!(len > 0.f) || !(len < kInfinity)) return false;
  *w = dir / len;
  return true;
}

// Barycentrics (b1, b2) of the point where p + t w meets the triangle's
// plane, clamped into the triangle (a direction from sample_spherical_triangle
// lies inside up to rounding).
TESSERA_HOST_DEVICE inline Vec2 triangle_barycentrics_along(const Vec3& p, const Vec3& w, const Vec3& v0,
                                                            const Vec3& v1, const Vec3& v2) {
  const Vec3 e1 = v1 - v0, e2 = v2 - v0;
  const Vec3 s1 = glm::cross(w, e2);
  const Float divisor = glm::dot(s1, e1);
  if (!(glm::abs(divisor) > 0.f)) return Vec2(1.f / 3.f);
  const Vec3 d = p - v0;
  Float b1 = glm::clamp(glm::dot(d, s1) / divisor, 0.f, 1.f);
  Float b2 = glm::clamp(glm::dot(w, glm::cross(d, e1)) / divisor, 0.f, 1.f);
  if (b1 + b2 > 1.f) {
    const Float sum = b1 + b2;
    b1 /= sum;
    b2 /= sum;
  }
  return Vec2(b1, b2);
}

}  // namespace tessera
