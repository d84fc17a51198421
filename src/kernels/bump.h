// pbrt-v4's bump mapping (BumpMap) and normal mapping (NormalMap): shading
// normals from a material's "displacement" float texture or "normalmap"
// image. Bump: the normal of the surface displaced along its normal by
// d(u, v), from finite differences of d; without ray differentials the step
// is pbrt-v4's fallback, 0.0005 in u and v (the point moved along dp/du,
// dp/dv by as much), and the d * dn/du term (curvature of interpolated
// normals) is left out. Normal map: the image's RGB as a
// tangent-space normal (2 rgb - 1) in the frame (dp/du, n).
#pragma once

#include "surface.h"
#include "texture_eval.h"

namespace tessera {

// pbrt-v4's shading dp/du, dp/dv at a hit: the triangle's, or with vertex
// normals ts = ns x dpdu, ss = ts x ns.
TESSERA_HOST_DEVICE inline void shading_derivatives(const SceneView& s, const SurfaceHit& h, Vec3* dpdu, Vec3* dpdv) {
  *dpdu = surface_dpdu(s, h);
  *dpdv = surface_dpdv(s, h);
  if (s.triangles[h.triangle].flags & kTriHasNormals) {
    const Vec3 ts = glm::cross(h.ns, *dpdu);
    if (glm::dot(ts, ts) > 0.f) {
      *dpdv = ts;
      *dpdu = glm::cross(ts, h.ns);
    }
  }
}

// pbrt: a perturbed shading normal faces the geometric normal's side.
TESSERA_HOST_DEVICE inline Vec3 faced_shading_normal(Vec3 n, const SurfaceHit& h) {
  const Float len = glm::length(n);
  if (!(len > 0.f) || !is_finite(n)) return h.ns;
  n /= len;
  return glm::dot(n, h.ng) < 0.f ? -n : n;
}

// Bump and normal maps are out of line on the GPU (device.h): only their
// materials take them.
TESSERA_HOST_DEVICE TESSERA_DEVICE_NOINLINE inline Vec3 bumped_shading_normal(const SceneView& s, int32_t bump,
                                                                          const SurfaceHit& h) {
  constexpr Float kDelta = 0.0005f;
  Vec3 dpdu, dpdv;
  shading_derivatives(s, h, &dpdu, &dpdv);
  // pbrt-v4 shifts both the uv and the point (along the shading dp/du, dp/dv),
  // so that 3D textures bump too.
  const TexturePoint at = texture_point(h);
  const Float d = eval_texture(s, bump, at).x;
  const Float du = eval_texture(s, bump, TexturePoint{h.p + kDelta * dpdu, h.ng, h.uv + Vec2(kDelta, 0.f)}).x;
  const Float dv = eval_texture(s, bump, TexturePoint{h.p + kDelta * dpdv, h.ng, h.uv + Vec2(0.f, kDelta)}).x;
  const Vec3 bu = dpdu + ((du - d) / kDelta) * h.ns, bv = dpdv + ((dv - d) / kDelta) * h.ns;
  return faced_shading_normal(glm::cross(bu, bv), h);
}

TESSERA_HOST_DEVICE TESSERA_DEVICE_NOINLINE inline Vec3 normal_mapped_shading_normal(const SceneView& s, int32_t image,
                                                                                 const SurfaceHit& h) {
  Vec3 dpdu, dpdv;
  shading_derivatives(s, h, &dpdu, &dpdv);
  const Rgb rgb = image_lookup(s.images[image], h.uv);
  const Vec3 local = 2.f * Vec3(rgb.x, rgb.y, rgb.z) - Vec3(1.f);
  const Float len = glm::length(local), ulen = glm::length(dpdu);
  if (!(len > 0.f) || !(ulen > 0.f)) return h.ns;
  // pbrt-v4's Frame::FromXZ(normalize(dpdu), ns).
  const Vec3 x = dpdu / ulen, z = h.ns, y = glm::cross(z, x);
  // pbrt then rebuilds dp/du, dp/dv around it, whose cross product is this normal again.
  return faced_shading_normal((local.x * x + local.y * y + local.z * z) / len, h);
}

}  // namespace tessera
