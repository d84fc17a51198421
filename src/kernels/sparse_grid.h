// A scalar field sampled on an integer lattice and stored in 8^3 bricks,
// read by trilinear interpolation (zero outside the lattice and in bricks
// that are not stored). Only bricks holding a non-zero value are stored, so
// a sparse cloud costs memory in proportion to what it holds (NanoVDB's
// grids are sparse in the same way); a dense "uniformgrid" uses the same
// layout so that one lookup serves every grid medium.
#pragma once

#include "vecmath.h"

namespace tessera {

constexpr int32_t kBrickLog2 = 3;
constexpr int32_t kBrickSide = 1 << kBrickLog2;
constexpr int32_t kBrickVoxels = kBrickSide * kBrickSide * kBrickSide;

struct SparseGridView {
  // World (render space) to lattice coordinates: value (x, y, z) sits at the
  // lattice point of those integer coordinates.
  Mat3 lattice_from_world{1.f};
  Vec3 lattice_from_world_offset{0.f};
  int32_t nx = 0, ny = 0, nz = 0;     // lattice points per axis; nx == 0: no grid
  int32_t bx = 0, by = 0, bz = 0;     // bricks per axis: (n + 7) / 8
  const int32_t* brick_of = nullptr;  // bx * by * bz, x fastest; -1: a brick of zeros
  const Float* values = nullptr;      // kBrickVoxels per stored brick, x fastest
};

TESSERA_HOST_DEVICE inline bool grid_present(const SparseGridView& g) { return g.nx > 0; }

TESSERA_HOST_DEVICE inline Vec3 grid_lattice_point(const SparseGridView& g, const Vec3& p_world) {
  return g.lattice_from_world * p_world + g.lattice_from_world_offset;
}

TESSERA_HOST_DEVICE inline Float lattice_value(const SparseGridView& g, int32_t x, int32_t y, int32_t z) {
  if (x < 0 || y < 0 || z < 0 || x >= g.nx || y >= g.ny || z >= g.nz) return 0.f;
  const int32_t brick =
      g.brick_of[(static_cast<size_t>(z >> kBrickLog2) * g.by + (y >> kBrickLog2)) * g.bx + (x >> kBrickLog2)];
  if (brick < 0) return 0.f;
  const int32_t m = kBrickSide - 1;
  return g.values[static_cast<size_t>(brick) * kBrickVoxels + (((z & m) * kBrickSide + (y & m)) * kBrickSide + (x & m))];
}

// Trilinear interpolation between the lattice points around p (lattice coordinates).
TESSERA_HOST_DEVICE inline Float lattice_trilinear(const SparseGridView& g, const Vec3& p) {
  if (!(p.x > -1.f && p.y > -1.f && p.z > -1.f && p.x < g.nx && p.y < g.ny && p.z < g.nz)) return 0.f;
  const int32_t ix = static_cast<int32_t>(glm::floor(p.x)), iy = static_cast<int32_t>(glm::floor(p.y)),
                iz = static_cast<int32_t>(glm::floor(p.z));
  const Float dx = p.x - ix, dy = p.y - iy, dz = p.z - iz;
  auto lerp = [](Float t, Float a, Float b) { return a + t * (b - a); };
  const Float d00 = lerp(dx, lattice_value(g, ix, iy, iz), lattice_value(g, ix + 1, iy, iz));
  const Float d10 = lerp(dx, lattice_value(g, ix, iy + 1, iz), lattice_value(g, ix + 1, iy + 1, iz));
  const Float d01 = lerp(dx, lattice_value(g, ix, iy, iz + 1), lattice_value(g, ix + 1, iy, iz + 1));
  const Float d11 = lerp(dx, lattice_value(g, ix, iy + 1, iz + 1), lattice_value(g, ix + 1, iy + 1, iz + 1));
  return lerp(dz, lerp(dy, d00, d10), lerp(dy, d01, d11));
}

TESSERA_HOST_DEVICE inline Float grid_value(const SparseGridView& g, const Vec3& p_world) {
  return lattice_trilinear(g, grid_lattice_point(g, p_world));
}

}  // namespace tessera
