// Reading PLY triangle meshes as pbrt-v4 does: ASCII and binary (either byte
// order), plain or gzip-compressed (.ply.gz).
#pragma once

#include <string>
#include <vector>

#include "kernels/device.h"

namespace tessera {

// Object-space geometry as stored in the file. Quads are split into two
// triangles (0,1,2) and (0,2,3), as pbrt-v4 does when it needs triangles;
// faces of other sizes are skipped (pbrt-v4 ignores them too) and counted.
// n and uv are empty when the file has none.
struct PlyMesh {
  std::vector<Vec3> p;
  std::vector<Vec3> n;
  std::vector<Vec2> uv;
  std::vector<uint32_t> indices;
  size_t skipped_faces = 0;  // faces with fewer than 3 or more than 4 vertices
  size_t quads = 0;          // quads, each made two triangles
};

// Parses a whole PLY file held in memory. `name` is used in messages only.
// Never reads out of bounds, never loops without consuming input: any
// malformed, truncated or hostile content throws
// SceneError("cannot read PLY '<name>': <reason>").
PlyMesh parse_ply_mesh(const std::string& bytes, const std::string& name);

// Reads `path` (gzip-compressed or not: the content decides, as zlib does)
// and parses it as it reads, chunk_bytes at a time: the file is never held
// whole (a compressed one is decompressed twice, first to learn its size).
// A header is read up to 16 MiB: no end_header by then is an error. Throws
// SceneError as parse_ply_mesh.
PlyMesh load_ply_mesh(const std::string& path, size_t chunk_bytes = size_t(1) << 20);

}  // namespace tessera
