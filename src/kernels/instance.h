// Object instancing (pbrt-v4's ObjectBegin / ObjectInstance): a prototype's
// triangles are stored once, in the space they were defined in, and each
// instance places them by an affine map, so that memory grows with unique
// geometry and not with the number of copies. Every backend traces an
// instance by carrying the ray into the prototype's space (the ray's t is
// the same there, as the map is affine), and the hit is carried back into
// render space once, when the surface is reconstructed (surface.h).
#pragma once

#include "vecmath.h"

namespace tessera {

// A prototype: triangles [first_triangle, first_triangle + num_triangles)
// of SceneView's arrays, which follow the world's own triangles.
struct ObjectPrototype {
  uint32_t first_triangle = 0;
  uint32_t num_triangles = 0;
};

// An affine map x -> linear x + offset.
struct Affine {
  Mat3 linear{1.f};
  Vec3 offset{0.f};
};

TESSERA_HOST_DEVICE inline Vec3 apply_point(const Affine& a, const Vec3& p) { return a.linear * p + a.offset; }
TESSERA_HOST_DEVICE inline Vec3 apply_vector(const Affine& a, const Vec3& v) { return a.linear * v; }

// One placed copy of a prototype. A moving instance (pbrt-v4's animated
// instance transform) is placed by the linear interpolation of its two
// matrices at the ray's time: every vertex then moves on a straight line, as
// a moving shape's vertices do (the flattened form's motion, exactly).
struct ObjectInstance {
  Affine render_from_object;      // at the start of the transform interval
  Affine object_from_render;      // its inverse
  Affine render_from_object_end;  // at the end (the start's when it does not move)
  uint32_t prototype = 0;
  uint32_t moves = 0;
};

// The instance's maps at a ray's time (0..1): both directions.
struct InstancePlacement {
  Affine render_from_object, object_from_render;
};

TESSERA_HOST_DEVICE inline InstancePlacement placement_at(const ObjectInstance& inst, Float time) {
  if (!inst.moves || !(time > 0.f)) return InstancePlacement{inst.render_from_object, inst.object_from_render};
  InstancePlacement p;
  const Affine &a = inst.render_from_object, &b = inst.render_from_object_end;
  p.render_from_object.linear = (1.f - time) * a.linear + time * b.linear;
  p.render_from_object.offset = glm::mix(a.offset, b.offset, time);
  // The loader refuses singular placements at either end; in between a
  // singular interpolant would make non-finite rays, which ray queries refuse.
  p.object_from_render.linear = glm::inverse(p.render_from_object.linear);
  p.object_from_render.offset = -(p.object_from_render.linear * p.render_from_object.offset);
  return p;
}

// A normal's map (the inverse transpose), unnormalised.
TESSERA_HOST_DEVICE inline Vec3 apply_normal(const InstancePlacement& p, const Vec3& n) {
  return glm::transpose(p.object_from_render.linear) * n;
}

// pbrt-v4's bound on the rounding error of an affine map applied to a point
// p known to within e per axis (Transform::operator()(Point3fi)).
TESSERA_HOST_DEVICE inline Vec3 mapped_point_error(const Affine& a, const Vec3& p, const Vec3& e) {
  constexpr Float kGamma3 = 3.f * 0x1p-24f / (1.f - 3.f * 0x1p-24f);
  Vec3 out;
  for (int r = 0; r < 3; ++r) {
    const Vec3 row(a.linear[0][r], a.linear[1][r], a.linear[2][r]);
    out[r] = (kGamma3 + 1.f) * glm::dot(abs3(row), e) + kGamma3 * (glm::dot(abs3(row), abs3(p)) + fabsf(a.offset[r]));
  }
  return out;
}

}  // namespace tessera
