// Builds the light tree of kernels/light_bvh.h on the host: each light's
// bounds (position, power, emission cone), then pbrt-v4's top-down build,
// which splits where a cost of power x solid angle of the cone x surface
// area is least (12 buckets per axis).
#pragma once

#include <vector>

#include "kernels/light_bvh.h"
#include "kernels/scene_view.h"

namespace tessera {

// What the tree knows of one light.
struct LightBounds {
  bool unbounded = false;  // infinite and distant lights: chosen apart from the tree
  Vec3 lo{0.f}, hi{0.f};
  double phi = 0.0;        // 0: the light emits nothing and is never chosen
  Vec3 w{0.f, 0.f, 1.f};
  double cos_o = -1.0, cos_e = 0.0;
  bool two_sided = false;
};

// The geometry area lights are bounded by (their triangles, at both ends of
// the shutter interval where shapes move).
struct LightGeometry {
  const Vec3* positions = nullptr;
  const Vec3* positions_end = nullptr;  // null: nothing moves
  const Vec3* normals = nullptr;
  const uint32_t* indices = nullptr;
  const TriangleInfo* triangles = nullptr;
  const Vec3* face_normals = nullptr;
};

// image_mean: the mean texel luminance of the light's image (1 without one).
LightBounds bounds_of_light(const Light& l, const LightGeometry& g, Float image_mean);

struct LightBvh {
  std::vector<LightBvhNode> nodes;
  std::vector<int32_t> leaf_of_light;
  std::vector<uint32_t> unbounded;
  LightBvhView view() const;
};

LightBvh build_light_bvh(const std::vector<LightBounds>& lights);

}  // namespace tessera
