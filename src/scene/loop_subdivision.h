// pbrt-v4's "loopsubdiv" shape: Loop subdivision of a triangle mesh, pushed
// to the limit surface, with the limit surface's normals as shading normals.
#pragma once

#include <string>
#include <vector>

#include "kernels/device.h"

namespace tessera {

struct SubdividedMesh {
  std::vector<Vec3> p;
  std::vector<Vec3> n;  // limit-surface normals (not normalised; may be zero where degenerate)
  std::vector<uint32_t> indices;
};

// Subdivides `levels` times with Loop's rules (pbrt-v4's: one-ring weights
// beta(valence), boundary edges and vertices by the crease rules) and moves
// every vertex to its limit position. `indices` must be in range (checked by
// the caller). Throws SceneError(reason) for meshes the rules are not
// defined on: an edge shared by more than two triangles, neighbours wound in
// opposite directions, a vertex whose triangles do not form one fan, or a
// result larger than kMaxSubdividedTriangles.
SubdividedMesh loop_subdivide(const std::vector<Vec3>& p, const std::vector<uint32_t>& indices, int levels);

constexpr size_t kMaxSubdividedTriangles = size_t(1) << 26;

}  // namespace tessera
