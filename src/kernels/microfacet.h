// Anisotropic Trowbridge-Reitz (GGX) microfacet distribution with
// visible-normal sampling; mirrors pbrt-v4's TrowbridgeReitzDistribution.
#pragma once

#include "vecmath.h"

namespace tessera {

TESSERA_HOST_DEVICE inline Float mf_cos_phi(const Vec3& w) {
  Float s = glm::sqrt(sin2_theta(w));
  return s == 0.f ? 1.f : glm::clamp(w.x / s, -1.f, 1.f);
}
TESSERA_HOST_DEVICE inline Float mf_sin_phi(const Vec3& w) {
  Float s = glm::sqrt(sin2_theta(w));
  return s == 0.f ? 0.f : glm::clamp(w.y / s, -1.f, 1.f);
}

struct TrowbridgeReitz {
  Float alpha_x, alpha_y;

  TESSERA_HOST_DEVICE TrowbridgeReitz(Float ax, Float ay) : alpha_x(ax), alpha_y(ay) {
    if (!effectively_smooth()) {  // as pbrt-v4: avoid numerical trouble with one tiny alpha
      alpha_x = glm::max(alpha_x, 1e-4f);
      alpha_y = glm::max(alpha_y, 1e-4f);
    }
  }
  TESSERA_HOST_DEVICE bool effectively_smooth() const { return !(glm::max(alpha_x, alpha_y) >= 1e-3f); }

  TESSERA_HOST_DEVICE Float D(const Vec3& wm) const {
    Float c2 = cos2_theta(wm);
    Float cos4 = c2 * c2;
    if (cos4 < 1e-16f) return 0.f;
    Float tan2 = sin2_theta(wm) / c2;
    if (!(tan2 <= 3.4e38f)) return 0.f;
    Float e = tan2 * (sqr(mf_cos_phi(wm) / alpha_x) + sqr(mf_sin_phi(wm) / alpha_y));
    Float d = 1.f / (kPi * alpha_x * alpha_y * cos4 * sqr(1.f + e));
    return d <= 3.4e38f ? d : 0.f;
  }
  TESSERA_HOST_DEVICE Float lambda(const Vec3& w) const {
    Float c2 = cos2_theta(w);
    if (c2 == 0.f) return 0.f;  // pbrt: IsInf(tan2) -> 0
    Float tan2 = sin2_theta(w) / c2;
    if (!(tan2 <= 3.4e38f)) return 0.f;
    Float alpha2 = sqr(mf_cos_phi(w) * alpha_x) + sqr(mf_sin_phi(w) * alpha_y);
    return (glm::sqrt(1.f + alpha2 * tan2) - 1.f) * 0.5f;
  }
  TESSERA_HOST_DEVICE Float G1(const Vec3& w) const { return 1.f / (1.f + lambda(w)); }
  TESSERA_HOST_DEVICE Float G(const Vec3& wo, const Vec3& wi) const { return 1.f / (1.f + lambda(wo) + lambda(wi)); }
  // Distribution of visible normals: G1(w)/|cos w| D(wm) |w.wm|.
  TESSERA_HOST_DEVICE Float D_visible(const Vec3& w, const Vec3& wm) const {
    Float c = abs_cos_theta(w);
    if (c == 0.f) return 0.f;
    return G1(w) / c * D(wm) * fabsf(glm::dot(w, wm));
  }
  TESSERA_HOST_DEVICE Float pdf(const Vec3& w, const Vec3& wm) const { return D_visible(w, wm); }

  // Samples a visible normal (always in the upper hemisphere) as seen from w.
  TESSERA_HOST_DEVICE Vec3 sample_wm(const Vec3& w, Vec2 u) const {
    Vec3 wh = glm::normalize(Vec3(alpha_x * w.x, alpha_y * w.y, w.z));
    if (wh.z < 0.f) wh = -wh;
    Vec3 t1 = (wh.z < 0.99999f) ? glm::normalize(glm::cross(Vec3(0.f, 0.f, 1.f), wh)) : Vec3(1.f, 0.f, 0.f);
    Vec3 t2 = glm::cross(wh, t1);
    // Uniform disk (polar mapping), then warp to the visible hemisphere.
    Float r = glm::sqrt(u.x), theta = 2.f * kPi * u.y;
    Vec2 p(r * glm::cos(theta), r * glm::sin(theta));
    Float h = safe_sqrt(1.f - p.x * p.x);
    Float t = (1.f + wh.z) * 0.5f;
    p.y = (1.f - t) * h + t * p.y;
    Float pz = safe_sqrt(1.f - p.x * p.x - p.y * p.y);
    Vec3 nh = p.x * t1 + p.y * t2 + pz * wh;
    return glm::normalize(Vec3(alpha_x * nh.x, alpha_y * nh.y, glm::max(1e-6f, nh.z)));
  }
};

}  // namespace tessera
