// Reconstructing the local geometry at a triangle hit from (primitive, barycentrics).
#pragma once

#include "scene_view.h"
#include "vecmath.h"

namespace tessera {

struct SurfaceHit {
  Vec3 p;      // position, interpolated from the vertices (more precise than o + t d)
  Vec3 ng;     // unit geometric normal, pbrt orientation (emission side of one-sided lights)
  Vec3 ns;     // unit shading normal (== ng without vertex normals)
  Vec2 uv;
  uint32_t triangle;
};

// b1, b2: barycentrics of vertices 1 and 2 (Embree's u, v).
TESSERA_HOST_DEVICE inline SurfaceHit make_surface_hit(const SceneView& s, uint32_t tri, Float b1, Float b2) {
  const uint32_t* idx = s.indices + 3 * static_cast<size_t>(tri);
  const TriangleInfo& info = s.triangles[tri];
  Float b0 = 1.f - b1 - b2;
  const Vec3& p0 = s.positions[idx[0]];
  const Vec3& p1 = s.positions[idx[1]];
  const Vec3& p2 = s.positions[idx[2]];
  SurfaceHit h;
  h.triangle = tri;
  h.p = b0 * p0 + b1 * p1 + b2 * p2;
  h.ng = s.face_normals[tri];
  h.ns = h.ng;
  if (info.flags & kTriHasNormals) {
    Vec3 ns = b0 * s.normals[idx[0]] + b1 * s.normals[idx[1]] + b2 * s.normals[idx[2]];
    Float l = glm::length(ns);
    if (l > 0.f) {
      h.ns = ns / l;
      // pbrt-v4: shading normals are authoritative for orientation.
      if (glm::dot(h.ng, h.ns) < 0.f) h.ng = -h.ng;
    }
  }
  if (info.flags & kTriHasUv) {
    h.uv = b0 * s.uvs[idx[0]] + b1 * s.uvs[idx[1]] + b2 * s.uvs[idx[2]];
  } else {
    h.uv = Vec2(b1 + b2, b2);  // pbrt's default (0,0), (1,0), (1,1)
  }
  return h;
}

// Ray origin pushed off the surface along the geometric normal, towards w.
TESSERA_HOST_DEVICE inline Vec3 offset_ray_origin(const SceneView& s, const Vec3& p, const Vec3& ng, const Vec3& w) {
  Float mag = glm::max(1.f, max_component(glm::abs(p)));
  Vec3 off = ng * (s.ray_epsilon * mag);
  return glm::dot(w, ng) >= 0.f ? p + off : p - off;
}

}  // namespace tessera
