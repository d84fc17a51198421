// How far out a scene may place things: every coordinate within
// +-kMaxSceneCoordinate (kernels/ray_guard.h), where single-precision ray
// tracing works (Embree takes no ray from beyond about 1.8e18, and hit
// points there are off by 1e11). Vertices, lights and the camera's rays
// beyond it are an error at load.
#pragma once

#include <glm/glm.hpp>
#include <string>

#include "kernels/ray_guard.h"

namespace tessera {

// Whether p (render space) is within the scene's limits; false for NaN.
inline bool representable(const Vec3& p) { return within(p, kMaxSceneCoordinate); }

// "at (x, y, z): beyond +-1e+18 (or not finite), where ...": `p` in render
// space, reported in the scene file's world (render space's origin added).
std::string describe_far(const Vec3& p, const glm::dvec3& origin = glm::dvec3(0.0));

}  // namespace tessera
