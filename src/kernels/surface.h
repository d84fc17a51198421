// Reconstructing the local geometry at a triangle hit from (primitive, barycentrics).
#pragma once

#include "scene_view.h"
#include "vecmath.h"

namespace tessera {

// What a closest-hit ray query reports.
struct TraceHit {
  Float t;
  uint32_t triangle;
  Float b1, b2;  // barycentrics of vertices 1 and 2
  // The ObjectInstance whose prototype holds the triangle; -1: the world's
  // own. Set by every ray query that reports a hit (no initialiser: path
  // state is not written twice per ray).
  int32_t instance;
};

struct SurfaceHit {
  Vec3 p;      // position, interpolated from the vertices (more precise than o + t d)
  Vec3 p_error;  // conservative bound on |p - exact| per axis (pbrt-v4's triangle bound)
  Vec3 ng;     // unit geometric normal, pbrt orientation (emission side of one-sided lights)
  Vec3 ns;     // unit shading normal (== ng without vertex normals)
  Vec2 uv;
  uint32_t triangle;
  int32_t instance;  // as TraceHit's (set by make_surface_hit): p, ng and ns are in render space either way
};

// The uv at barycentrics (b1, b2): interpolated, or pbrt's default
// (0,0), (1,0), (1,1) for triangles without uv ((0,0), (1,1), (0,1) for a
// quad's second half, so that the quad reads its patch's uv).
TESSERA_HOST_DEVICE inline Vec2 triangle_uv(const SceneView& s, uint32_t tri, Float b1, Float b2) {
  const uint32_t flags = s.triangles[tri].flags;
  if (!(flags & kTriHasUv)) return (flags & kTriQuadSecondHalf) ? Vec2(b1, b1 + b2) : Vec2(b1 + b2, b2);
  const uint32_t* idx = s.indices + 3 * static_cast<size_t>(tri);
  return (1.f - b1 - b2) * s.uvs[idx[0]] + b1 * s.uvs[idx[1]] + b2 * s.uvs[idx[2]];
}

// pbrt-v4's gamma(7): the relative rounding bound of a 7-operation float expression.
constexpr Float kGamma7 = 7.f * 0x1p-24f / (1.f - 7.f * 0x1p-24f);

// The ray that found a hit: its point o + t d is the alternative to the
// barycentric one (see refine_huge_triangle_hit).
struct RayPoint {
  Vec3 o, d;
  Float t;
};

// A hit on a triangle much larger than its distance from the origin (a
// ground plane 1e8 across seen from a camera at render space's origin): the
// barycentric point sums terms the size of the triangle, so its error is
// that size times float epsilon, metres for 1e8. The ray's point o + t d is
// then far more precise along the plane, and its error across the plane
// (t's rounding) is removed by projecting onto the plane, computed in
// double from the vertices (their differences and cross product are exact
// enough there). Leaves the hit alone unless that gains a factor of 16, so
// ordinary triangles never pay for the double arithmetic.
TESSERA_HOST_DEVICE inline void refine_huge_triangle_hit(SurfaceHit& h, const Vec3& p0, const Vec3& p1, const Vec3& p2,
                                                         const RayPoint& r) {
  const Vec3 p_ray = r.o + r.t * r.d;
  const Vec3 ray_error = kGamma7 * (abs3(r.o) + abs3(r.t * r.d));
  const Float bary = glm::max(h.p_error.x, glm::max(h.p_error.y, h.p_error.z));
  const Float ray = glm::max(ray_error.x, glm::max(ray_error.y, ray_error.z));
  if (!(bary > 16.f * ray) || !(r.t < kInfinity)) return;
  const glm::dvec3 q0(p0), n = glm::cross(glm::dvec3(p1) - q0, glm::dvec3(p2) - q0);
  const double len = glm::length(n);
  if (!(len > 0.0)) return;
  glm::dvec3 x(p_ray);
  x -= (glm::dot(n, x - q0) / (len * len)) * n;
  h.p = Vec3(x);
  h.p_error = kGamma7 * abs3(h.p) + ray_error;
}

// A triangle's vertices at a ray's time: a moving triangle's interpolated
// linearly between its two placements, as Embree intersects it. Every
// backend and the hit reconstruction read them here.
TESSERA_HOST_DEVICE inline void triangle_vertices_at(const SceneView& s, uint32_t tri, Float time, Vec3* p0, Vec3* p1,
                                                     Vec3* p2) {
  const uint32_t* idx = s.indices + 3 * static_cast<size_t>(tri);
  *p0 = s.positions[idx[0]];
  *p1 = s.positions[idx[1]];
  *p2 = s.positions[idx[2]];
  if (s.positions_end && time > 0.f) {
    *p0 = glm::mix(*p0, s.positions_end[idx[0]], time);
    *p1 = glm::mix(*p1, s.positions_end[idx[1]], time);
    *p2 = glm::mix(*p2, s.positions_end[idx[2]], time);
  }
}

// b1, b2: barycentrics of vertices 1 and 2 (Embree's u, v); time: the ray's
// (Ray::time); ray: the ray that found the hit, if a ray did (huge
// triangles take their point from it).
TESSERA_HOST_DEVICE TESSERA_INLINE SurfaceHit make_surface_hit(const SceneView& s, uint32_t tri, Float b1, Float b2,
                                                               Float time = 0.f, const RayPoint* ray = nullptr) {
  const uint32_t* idx = s.indices + 3 * static_cast<size_t>(tri);
  const TriangleInfo& info = s.triangles[tri];
  Float b0 = 1.f - b1 - b2;
  Vec3 p0, p1, p2;
  triangle_vertices_at(s, tri, time, &p0, &p1, &p2);
  const bool moving = s.positions_end && time > 0.f;
  SurfaceHit h;
  h.triangle = tri;
  h.instance = -1;
  h.p = b0 * p0 + b1 * p1 + b2 * p2;
  // pbrt-v4: gamma(7) * sum |b_i p_i| bounds the rounding error of h.p.
  h.p_error = kGamma7 * (abs3(b0 * p0) + abs3(b1 * p1) + abs3(b2 * p2));
  if (ray) refine_huge_triangle_hit(h, p0, p1, p2, *ray);
  h.ng = s.face_normals[tri];
  if (moving) {
    Vec3 n;
    if (triangle_normal(p0, p1, p2, &n, nullptr)) h.ng = (info.flags & kTriFlipNormal) ? -n : n;
  }
  h.ns = h.ng;
  if (info.flags & kTriHasNormals) {
    Vec3 ns = b0 * s.normals[idx[0]] + b1 * s.normals[idx[1]] + b2 * s.normals[idx[2]];
    if (moving)
      ns = glm::mix(ns, b0 * s.normals_end[idx[0]] + b1 * s.normals_end[idx[1]] + b2 * s.normals_end[idx[2]], time);
    Float l = glm::length(ns);
    if (l > 0.f) {
      h.ns = ns / l;
      // pbrt-v4: shading normals are authoritative for orientation.
      if (glm::dot(h.ng, h.ns) < 0.f) h.ng = -h.ng;
    }
  }
  h.uv = triangle_uv(s, tri, b1, b2);
  return h;
}

// A hit on an instance's prototype: reconstructed in the prototype's space
// (where its vertices are), then carried into render space; the normals by
// the inverse transpose, ng turned to ns's side again as make_surface_hit
// does (a non-uniform scale can change which side that is). Out of line and
// given values only, so that the world's hits do not pay for it in registers.
TESSERA_HOST_DEVICE TESSERA_NOINLINE SurfaceHit make_instanced_surface_hit(const SceneView& s, TraceHit hit, Float time,
                                                                           bool has_ray, RayPoint ray) {
  const InstancePlacement place = placement_at(s.instances[hit.instance], time);
  RayPoint local;
  if (has_ray) local = RayPoint{apply_point(place.object_from_render, ray.o), apply_vector(place.object_from_render, ray.d), ray.t};
  SurfaceHit h = make_surface_hit(s, hit.triangle, hit.b1, hit.b2, time, has_ray ? &local : nullptr);
  h.instance = hit.instance;
  h.p_error = mapped_point_error(place.render_from_object, h.p, h.p_error);
  h.p = apply_point(place.render_from_object, h.p);
  const bool smooth = h.ns != h.ng;
  Vec3 ng = apply_normal(place, h.ng);
  const Float ng_len = glm::length(ng);
  if (ng_len > 0.f) h.ng = ng / ng_len;
  if (smooth) {
    const Vec3 ns = apply_normal(place, h.ns);
    const Float ns_len = glm::length(ns);
    h.ns = ns_len > 0.f ? ns / ns_len : h.ng;
    if (glm::dot(h.ng, h.ns) < 0.f) h.ng = -h.ng;
  } else {
    h.ns = h.ng;
  }
  return h;
}

// The surface at a ray query's hit, on the world's triangles or an instance's.
TESSERA_HOST_DEVICE TESSERA_INLINE SurfaceHit make_surface_hit(const SceneView& s, const TraceHit& hit, Float time = 0.f,
                                                               const RayPoint* ray = nullptr) {
  if (hit.instance >= 0) return make_instanced_surface_hit(s, hit, time, ray != nullptr, ray ? *ray : RayPoint{});
  return make_surface_hit(s, hit.triangle, hit.b1, hit.b2, time, ray);
}

// Ray origin pushed off the surface along the geometric normal, towards w,
// by the rounding-error bound of the hit point (pbrt-v4's OffsetRayOrigin),
// with a safety factor for Embree's own intersection arithmetic. Scale-free:
// a scene modelled in millimetres or in kilometres gets the same relative offset.
TESSERA_HOST_DEVICE TESSERA_INLINE Vec3 offset_ray_origin(const Vec3& p, const Vec3& p_error, const Vec3& ng, const Vec3& w) {
  constexpr Float kSafety = 16.f;
  Float d = kSafety * glm::dot(abs3(ng), p_error) + 1e-30f;
  Vec3 off = d * ng;
  return glm::dot(w, ng) >= 0.f ? p + off : p - off;
}
TESSERA_HOST_DEVICE TESSERA_INLINE Vec3 offset_ray_origin(const SurfaceHit& h, const Vec3& w) {
  return offset_ray_origin(h.p, h.p_error, h.ng, w);
}

// A direction sampled in the shading frame can fall on the wrong side of the
// flat face: smooth normals of a tessellated surface (our spheres, 64 x 128
// facets) differ from the face by up to half a facet's angle, so a
// reflection may graze through the face, or, where wo itself grazes the face
// and lies on the other side of the shading normal, a whole hemisphere of
// reflections points into the object. offset_ray_origin then starts the ray
// on the far side: inside a closed object it escapes and its light is lost
// (an albedo-1 sphere furnace at depth 1000 lost 7 %, unguided; limiting
// this to directions within 3 or 11 degrees of the face still lost 2 %).
// Such a ray leaves mirrored across the face instead, on the side its lobe
// meant, keeping the sampled direction's weight and pdf: a small error in
// the direction of rare grazing rays instead of pbrt-v4's, which sends them
// through the surface. Not for delta lobes, whose direction is exact.
TESSERA_HOST_DEVICE inline Vec3 keep_on_lobe_side(const Vec3& wi, const Vec3& wo, const Vec3& ng, bool transmission) {
  const Float i = glm::dot(wi, ng), o = glm::dot(wo, ng);
  if (i == 0.f || o == 0.f || ((i > 0.f) == (o > 0.f)) != transmission) return wi;
  return glm::normalize(wi - 2.f * i * ng);
}

// dp/du (axis 0) or dp/dv (axis 1) of the triangle's uv parametrisation
// (pbrt-v4 Triangle), for shading frames of anisotropic BSDFs and bump
// mapping; falls back to a tangent of the face when uvs are degenerate.
TESSERA_HOST_DEVICE inline Vec3 surface_dp_duv(const SceneView& s, uint32_t tri, int axis) {
  const uint32_t* idx = s.indices + 3 * static_cast<size_t>(tri);
  Vec2 uv0(0.f, 0.f), uv1(1.f, 0.f), uv2(1.f, 1.f);
  if (s.triangles[tri].flags & kTriQuadSecondHalf) {
    uv1 = Vec2(1.f, 1.f);
    uv2 = Vec2(0.f, 1.f);
  }
  if (s.triangles[tri].flags & kTriHasUv) {
    uv0 = s.uvs[idx[0]];
    uv1 = s.uvs[idx[1]];
    uv2 = s.uvs[idx[2]];
  }
  const Vec2 duv02 = uv0 - uv2, duv12 = uv1 - uv2;
  const Vec3 dp02 = s.positions[idx[0]] - s.positions[idx[2]], dp12 = s.positions[idx[1]] - s.positions[idx[2]];
  const Float det = duv02.x * duv12.y - duv02.y * duv12.x;
  const Frame fallback = Frame::from_z(s.face_normals[tri]);
  if (fabsf(det) < 1e-9f) return axis == 0 ? fallback.s : fallback.t;
  const Vec3 d = axis == 0 ? (duv12.y * dp02 - duv02.y * dp12) / det : (-duv12.x * dp02 + duv02.x * dp12) / det;
  if (!(glm::dot(d, d) > 0.f) || !is_finite(d)) return axis == 0 ? fallback.s : fallback.t;
  return d;
}
// In the triangle's own space (render space, or its prototype's).
TESSERA_HOST_DEVICE inline Vec3 surface_dpdu(const SceneView& s, uint32_t tri) { return surface_dp_duv(s, tri, 0); }
TESSERA_HOST_DEVICE inline Vec3 surface_dpdv(const SceneView& s, uint32_t tri) { return surface_dp_duv(s, tri, 1); }

// A vector of an instance's prototype in render space (out of line: the
// world's hits do not pay for it in code size where they are inlined).
TESSERA_HOST_DEVICE TESSERA_NOINLINE Vec3 instance_vector_to_render(const SceneView& s, int32_t instance, Vec3 d, Float time) {
  return apply_vector(placement_at(s.instances[instance], time).render_from_object, d);
}

// In render space: an instance's tangents carried out of its prototype's space.
TESSERA_HOST_DEVICE inline Vec3 surface_dp_duv(const SceneView& s, const SurfaceHit& h, int axis, Float time) {
  const Vec3 d = surface_dp_duv(s, h.triangle, axis);
  return h.instance < 0 ? d : instance_vector_to_render(s, h.instance, d, time);
}
TESSERA_HOST_DEVICE inline Vec3 surface_dpdu(const SceneView& s, const SurfaceHit& h, Float time = 0.f) {
  return surface_dp_duv(s, h, 0, time);
}
TESSERA_HOST_DEVICE inline Vec3 surface_dpdv(const SceneView& s, const SurfaceHit& h, Float time = 0.f) {
  return surface_dp_duv(s, h, 1, time);
}

}  // namespace tessera
