// Warping functions from uniform samples to directions and points, with their pdfs.
#pragma once

#include "vecmath.h"

namespace tessera {

TESSERA_HOST_DEVICE inline Vec2 sample_uniform_disk_concentric(Vec2 u) {
  Vec2 o = 2.f * u - Vec2(1.f);
  if (o.x == 0.f && o.y == 0.f) return Vec2(0.f);
  Float r, theta;
  if (fabsf(o.x) > fabsf(o.y)) {
    r = o.x;
    theta = (kPi / 4.f) * (o.y / o.x);
  } else {
    r = o.y;
    theta = kPi / 2.f - (kPi / 4.f) * (o.x / o.y);
  }
  return r * Vec2(glm::cos(theta), glm::sin(theta));
}

TESSERA_HOST_DEVICE inline Vec3 sample_cosine_hemisphere(Vec2 u) {
  Vec2 d = sample_uniform_disk_concentric(u);
  Float z = safe_sqrt(1.f - d.x * d.x - d.y * d.y);
  return Vec3(d.x, d.y, z);
}
TESSERA_HOST_DEVICE inline Float cosine_hemisphere_pdf(Float cos_theta) { return cos_theta * kInvPi; }

TESSERA_HOST_DEVICE inline Vec3 sample_uniform_sphere(Vec2 u) {
  Float z = 1.f - 2.f * u.x;
  Float r = safe_sqrt(1.f - z * z);
  Float phi = 2.f * kPi * u.y;
  return Vec3(r * glm::cos(phi), r * glm::sin(phi), z);
}
constexpr Float kUniformSpherePdf = kInv4Pi;

// Barycentrics (b0, b1, b2) uniformly distributed over a triangle (pbrt-v4's
// area-preserving mapping).
TESSERA_HOST_DEVICE inline Vec3 sample_uniform_triangle(Vec2 u) {
  Float b0, b1;
  if (u.x < u.y) {
    b0 = u.x / 2.f;
    b1 = u.y - b0;
  } else {
    b1 = u.y / 2.f;
    b0 = u.x - b1;
  }
  return Vec3(b0, b1, 1.f - b0 - b1);
}

// MIS power heuristic with beta = 2 for one sample of each strategy.
TESSERA_HOST_DEVICE inline Float power_heuristic(Float pdf_a, Float pdf_b) {
  Float a = pdf_a * pdf_a, b = pdf_b * pdf_b;
  if (a == 0.f && b == 0.f) return 0.f;
  // Guard against overflow for huge (near-delta) pdfs: the ratio is what matters.
  if (a > 1e30f || b > 1e30f) return pdf_a >= pdf_b ? 1.f : 0.f;
  return a / (a + b);
}

TESSERA_HOST_DEVICE inline Float balance_heuristic(Float pdf_a, Float pdf_b) {
  const Float sum = pdf_a + pdf_b;
  if (!(sum > 0.f)) return 0.f;
  if (sum > 1e30f) return pdf_a >= pdf_b ? 1.f : 0.f;
  return pdf_a / sum;
}

// The MIS weight of strategy a against b: the balance heuristic (pbrt-v4's
// volpath) or the power heuristic (its path integrator).
TESSERA_HOST_DEVICE inline Float mis_weight(Float pdf_a, Float pdf_b, bool balance) {
  return balance ? balance_heuristic(pdf_a, pdf_b) : power_heuristic(pdf_a, pdf_b);
}

}  // namespace tessera
