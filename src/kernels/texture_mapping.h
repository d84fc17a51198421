// The coordinates a texture reads at a surface point: pbrt-v4's 2D mappings
// (uv, spherical, cylindrical, planar) and its 3D point mapping. Point
// sampling: no ray differentials, so no filter footprints.
#pragma once

#include "material.h"
#include "vecmath.h"

namespace tessera {

// What pbrt-v4's TextureEvalContext holds that our textures read: the point
// (render space), the unit geometric normal and the surface's uv.
struct TexturePoint {
  Vec3 p;
  Vec3 n;
  Vec2 uv;
};

TESSERA_HOST_DEVICE inline Vec3 texture_space_point(const Texture& t, const Vec3& p) {
  return Vec3(t.texture_from_render * Vec4(p, 1.f));
}

// pbrt-v4's SphericalMapping: (theta / pi, phi / 2 pi) of the direction from
// the texture-space origin, z the pole. The origin itself maps to (0, 0).
TESSERA_HOST_DEVICE inline Vec2 spherical_st(const Vec3& q) {
  const Float len = glm::length(q);
  if (!(len > 0.f) || !(len < kInfinity)) return Vec2(0.f);
  const Vec3 d = q / len;
  const Float theta = glm::acos(glm::clamp(d.z, -1.f, 1.f));
  Float phi = glm::atan(d.y, d.x);
  if (phi < 0.f) phi += 2.f * kPi;
  return Vec2(theta / kPi, phi / (2.f * kPi));
}

// pbrt-v4's CylindricalMapping: the angle about z over 2 pi (0 along -x), and z.
TESSERA_HOST_DEVICE inline Vec2 cylindrical_st(const Vec3& q) {
  return Vec2((kPi + glm::atan(q.y, q.x)) / (2.f * kPi), q.z);
}

TESSERA_HOST_DEVICE inline Vec2 texture_st(const Texture& t, const TexturePoint& tp) {
  switch (t.mapping) {
    case TextureMapping::Spherical:
      return spherical_st(texture_space_point(t, tp.p));
    case TextureMapping::Cylindrical:
      return cylindrical_st(texture_space_point(t, tp.p));
    case TextureMapping::Planar: {
      const Vec3 q = texture_space_point(t, tp.p);
      return Vec2(t.du + glm::dot(q, t.vs), t.dv + glm::dot(q, t.vt));
    }
    default:
      return Vec2(t.su * tp.uv.x + t.du, t.sv * tp.uv.y + t.dv);
  }
}

}  // namespace tessera
