// pbrt-v4's bump mapping (BumpMap): the shading normal of a surface displaced
// along its normal by a float texture d(u, v), from finite differences of d.
// Without ray differentials the step is pbrt-v4's fallback, 0.0005 in u and
// v; the d * dn/du term (curvature of interpolated normals) is left out.
#pragma once

#include "surface.h"
#include "texture_eval.h"

namespace tessera {

TESSERA_HOST_DEVICE inline Vec3 bumped_shading_normal(const SceneView& s, int32_t bump, const SurfaceHit& h) {
  constexpr Float kDelta = 0.0005f;
  Vec3 dpdu = surface_dpdu(s, h.triangle), dpdv = surface_dpdv(s, h.triangle);
  if (s.triangles[h.triangle].flags & kTriHasNormals) {
    // pbrt-v4's shading frame with vertex normals: ts = ns x dpdu, ss = ts x ns.
    const Vec3 ts = glm::cross(h.ns, dpdu);
    if (glm::dot(ts, ts) > 0.f) {
      dpdv = ts;
      dpdu = glm::cross(ts, h.ns);
    }
  }
  const Float d = eval_texture(s, bump, h.uv).x;
  const Float du = eval_texture(s, bump, h.uv + Vec2(kDelta, 0.f)).x;
  const Float dv = eval_texture(s, bump, h.uv + Vec2(0.f, kDelta)).x;
  const Vec3 bu = dpdu + ((du - d) / kDelta) * h.ns, bv = dpdv + ((dv - d) / kDelta) * h.ns;
  Vec3 n = glm::cross(bu, bv);
  const Float len = glm::length(n);
  if (!(len > 0.f) || !is_finite(n)) return h.ns;
  n /= len;
  return glm::dot(n, h.ng) < 0.f ? -n : n;  // pbrt: the bumped normal faces the geometric normal's side
}

}  // namespace tessera
