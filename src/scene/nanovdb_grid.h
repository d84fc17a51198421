// Float grids from NanoVDB files (pbrt-v4's "nanovdb" medium), read with the
// NanoVDB library (libnanovdb-dev) and copied into our brick lattice: NanoVDB
// leaves are 8^3 voxels, so each leaf becomes one brick, and constant tiles
// of the internal nodes become bricks of their value. The kernels then need
// no NanoVDB type, on the CPU or a GPU. The file's container is read by our
// own code, not NanoVDB's io::readGrid: that one trusts the sizes in the file
// (a damaged file makes it read past its buffers or allocate what it says).
#pragma once

#include <string>

#include "scene/sparse_grid_build.h"

namespace tessera {

struct NanoVdbGrid {
  bool found = false;
  // Its lattice; lattice_from_world maps the grid's world space (pbrt-v4's
  // medium space) to lattice coordinates: NanoVDB's index coordinates shifted
  // so that the lowest stored brick starts at 0.
  SparseGridDesc lattice;
  Vec3 world_lo{0.f}, world_hi{0.f};  // NanoVDB's worldBBox (medium space)
};

// The float grid `name` of `path`; found == false when the file has no grid
// of that name. A density must be finite and not negative, with a zero
// background; other grids (temperature) only finite, their background kept.
// Throws std::runtime_error for an unreadable file, a corrupt grid, or a
// grid that is not a float fog volume (as pbrt-v4 requires); world_lo ==
// world_hi for a grid with no active voxel.
NanoVdbGrid read_nanovdb_grid(const std::string& path, const std::string& name, bool density);

}  // namespace tessera
