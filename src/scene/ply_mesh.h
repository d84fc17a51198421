// Reading PLY triangle meshes (ASCII and binary) through Assimp.
#pragma once

#include <string>
#include <vector>

#include "kernels/device.h"

namespace tessera {

// Object-space geometry as stored in the file; quads and polygons are split
// into triangles. n and uv are empty when the file has none.
struct PlyMesh {
  std::vector<Vec3> p;
  std::vector<Vec3> n;
  std::vector<Vec2> uv;
  std::vector<uint32_t> indices;
};

// Throws SceneError("cannot read PLY '<path>': <reason>").
PlyMesh load_ply_mesh(const std::string& path);

}  // namespace tessera
