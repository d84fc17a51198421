// pbrt-v4's displacement of "plymesh" shapes ("texture displacement",
// "edgelength"): the mesh is refined by splitting longest edges until every
// edge is shorter than edgelength in world space, each vertex is moved along
// its normal by the texture's value at its uv, and normals are recomputed.
#pragma once

#include <functional>

#include "kernels/scene_view.h"
#include "scene/scene_desc.h"

namespace tessera {

// A float texture's value at a vertex: its object-space point (where pbrt-v4
// evaluates displacement) and its uv.
using DisplacementFn = std::function<Float(const Vec3& p, Vec2 uv)>;

// Displaces an object-space mesh in place (quads already split). Throws
// SceneError(reason) when the mesh has no uv (pbrt-v4 requires them), the
// edge length is not positive or refinement would exceed kMaxDisplacedTriangles.
void displace_mesh(MeshDesc& mesh, const Mat4& world_from_object, Float edge_length, const DisplacementFn& displacement);

constexpr size_t kMaxDisplacedTriangles = size_t(1) << 25;

// Unit vertex normals: the normalised sum of the unit normals of the faces
// around each vertex, as pbrt-v4's TriQuadMesh::ComputeNormals (a vertex on
// no face keeps (0, 0, 0)).
std::vector<Vec3> vertex_normals(const std::vector<Vec3>& p, const std::vector<uint32_t>& indices);

// Evaluates float textures of a scene being loaded, on the host.
class HostTextures {
 public:
  explicit HostTextures(const SceneDesc& scene);
  Float eval(const TextureSlot& slot, const Vec3& p, const Vec3& n, Vec2 uv) const;

 private:
  std::vector<ImageView> images_;
  SceneView view_;
};

}  // namespace tessera
