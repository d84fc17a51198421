// A scalar field sampled on an integer lattice and stored in 8^3 bricks,
// read by trilinear interpolation (the background value, normally 0,
// outside the lattice and in bricks that are not stored). Only bricks holding a non-zero value are stored, so
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
  const int32_t* brick_of = nullptr;  // bx * by * bz, x fastest; -1: a brick of the background
  const Float* values = nullptr;      // kBrickVoxels per stored brick, x fastest
  Float background = 0.f;
};

TESSERA_HOST_DEVICE inline bool grid_present(const SparseGridView& g) { return g.nx > 0; }

TESSERA_HOST_DEVICE inline Vec3 grid_lattice_point(const SparseGridView& g, const Vec3& p_world) {
  return g.lattice_from_world * p_world + g.lattice_from_world_offset;
}

TESSERA_HOST_DEVICE inline Float lattice_value(const SparseGridView& g, int32_t x, int32_t y, int32_t z) {
  if (x < 0 || y < 0 || z < 0 || x >= g.nx || y >= g.ny || z >= g.nz) return g.background;
  const int32_t brick =
      g.brick_of[(static_cast<size_t>(z >> kBrickLog2) * g.by + (y >> kBrickLog2)) * g.bx + (x >> kBrickLog2)];
  if (brick < 0) return g.background;
  const int32_t m = kBrickSide - 1;
  return g.values[static_cast<size_t>(brick) * kBrickVoxels + (((z & m) * kBrickSide + (y & m)) * kBrickSide + (x & m))];
}

// The lattice cell around p (lattice coordinates) and p's place in it;
// false where every surrounding lattice point is outside (or p is NaN).
struct LatticeCell {
  int32_t x, y, z;   // the corner with the smallest coordinates
  Float dx, dy, dz;  // in [0, 1)
};

TESSERA_HOST_DEVICE inline bool lattice_cell(const SparseGridView& g, const Vec3& p, LatticeCell* c) {
  if (!(p.x > -1.f && p.y > -1.f && p.z > -1.f && p.x < g.nx && p.y < g.ny && p.z < g.nz)) return false;
  c->x = static_cast<int32_t>(glm::floor(p.x));
  c->y = static_cast<int32_t>(glm::floor(p.y));
  c->z = static_cast<int32_t>(glm::floor(p.z));
  c->dx = p.x - c->x;
  c->dy = p.y - c->y;
  c->dz = p.z - c->z;
  return true;
}

// Corner k (bit 0: +x, bit 1: +y, bit 2: +z) of the cell and its trilinear weight.
TESSERA_HOST_DEVICE inline Float lattice_corner(const LatticeCell& c, int k, int32_t* x, int32_t* y, int32_t* z) {
  *x = c.x + (k & 1);
  *y = c.y + ((k >> 1) & 1);
  *z = c.z + (k >> 2);
  return ((k & 1) ? c.dx : 1.f - c.dx) * (((k >> 1) & 1) ? c.dy : 1.f - c.dy) * ((k >> 2) ? c.dz : 1.f - c.dz);
}

// Trilinear interpolation between the lattice points around p (lattice coordinates).
TESSERA_HOST_DEVICE inline Float lattice_trilinear(const SparseGridView& g, const Vec3& p) {
  LatticeCell c;
  if (!lattice_cell(g, p, &c)) return g.background;
  auto lerp = [](Float t, Float a, Float b) { return a + t * (b - a); };
  const int32_t ix = c.x, iy = c.y, iz = c.z;
  const Float d00 = lerp(c.dx, lattice_value(g, ix, iy, iz), lattice_value(g, ix + 1, iy, iz));
  const Float d10 = lerp(c.dx, lattice_value(g, ix, iy + 1, iz), lattice_value(g, ix + 1, iy + 1, iz));
  const Float d01 = lerp(c.dx, lattice_value(g, ix, iy, iz + 1), lattice_value(g, ix + 1, iy, iz + 1));
  const Float d11 = lerp(c.dx, lattice_value(g, ix, iy + 1, iz + 1), lattice_value(g, ix + 1, iy + 1, iz + 1));
  return lerp(c.dz, lerp(c.dy, d00, d10), lerp(c.dy, d01, d11));
}

TESSERA_HOST_DEVICE inline Float grid_value(const SparseGridView& g, const Vec3& p_world) {
  return lattice_trilinear(g, grid_lattice_point(g, p_world));
}

}  // namespace tessera
