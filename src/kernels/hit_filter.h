// Candidate hits a ray query skips, for every backend: alpha cutouts
// (alpha.h) and the one-way faces of curve tubes (kTriInvisibleFromInside).
#pragma once

#include "alpha.h"

namespace tessera {

// Whether a ray query skips this candidate hit: a one-way face met from
// inside (along its outward normal, at the ray's time for a moving tube), or
// an alpha cutout. Backends call it for every candidate when the scene has
// either (SceneView::triangle_alpha, has_one_way_faces). instance: the
// candidate's (TraceHit::instance); o and d are then in its prototype's
// space, where the face normal is (an affine map keeps the sign of d . n).
TESSERA_HOST_DEVICE inline bool hit_ignored(const SceneView& s, uint32_t tri, int32_t instance, Float b1, Float b2,
                                            const Vec3& o, const Vec3& d, Float time) {
  const TriangleInfo& info = s.triangles[tri];
  if (info.flags & kTriInvisibleFromInside) {
    Vec3 n = s.face_normals[tri];
    if (s.positions_end && time > 0.f) {
      Vec3 p0, p1, p2, moved;
      triangle_vertices_at(s, tri, time, &p0, &p1, &p2);
      if (triangle_normal(p0, p1, p2, &moved, nullptr)) n = (info.flags & kTriFlipNormal) ? -moved : moved;
    }
    if (glm::dot(d, n) > 0.f) return true;
  }
  return s.triangle_alpha && alpha_ignores_hit(s, tri, instance, b1, b2, o, d, time);
}

}  // namespace tessera
