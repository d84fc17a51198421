// Host-side storage of the grid media's lattices (kernels/sparse_grid.h
// reads them) and of their majorant grids (kernels/majorant_grid.h).
#pragma once

#include <cstdint>
#include <vector>

#include "kernels/majorant_grid.h"
#include "kernels/sparse_grid.h"

namespace tessera {

struct SparseGridDesc {
  Mat4 lattice_from_world{1.f};
  int32_t nx = 0, ny = 0, nz = 0;  // nx == 0: no grid
  int32_t bx = 0, by = 0, bz = 0;
  std::vector<int32_t> brick_of;   // bx * by * bz, -1: the background
  std::vector<Float> values;       // kBrickVoxels per stored brick
  Float max_value = 0.f;           // of the stored values and the background
  Float background = 0.f;          // outside the lattice and in bricks not stored
};

// Fills a SparseGridDesc point by point; the background value never
// allocates a brick, and constant bricks (NanoVDB's tiles) share one.
class SparseGridBuilder {
 public:
  SparseGridBuilder(int32_t nx, int32_t ny, int32_t nz, Float background = 0.f);
  void set(int32_t x, int32_t y, int32_t z, Float v);  // x, y, z inside the lattice
  void fill_brick(int32_t bx, int32_t by, int32_t bz, Float v);  // brick coordinates inside the lattice
  SparseGridDesc finish(const Mat4& lattice_from_world);

 private:
  int32_t new_brick(Float fill);
  SparseGridDesc g_;
  std::vector<uint8_t> shared_;  // per stored brick: filled by fill_brick, copied before set() changes it
  int32_t shared_brick_ = -1;    // the last brick fill_brick made
};

// A dense grid (nx * ny * nz values, x fastest) as pbrt-v4's SampledGrid
// places it: values at the voxel centres of the box p0..p1 of the medium's
// space, which medium_from_world maps world points into.
SparseGridDesc sparse_grid_from_dense(const std::vector<Float>& values, int32_t nx, int32_t ny, int32_t nz,
                                      const Vec3& p0, const Vec3& p1, const Mat4& medium_from_world);

struct MajorantGridDesc {
  Vec3 lo{0.f}, hi{1.f};  // lattice coordinates of the grid it bounds
  int32_t nx = 1, ny = 1, nz = 1;
  std::vector<Float> max_density;
};

// Bounds of `g` over cells of the box lo..hi (lattice coordinates): each
// cell holds the largest value of the lattice points its trilinear lookups
// can reach, so no lookup inside the cell exceeds it.
MajorantGridDesc build_majorant_grid(const SparseGridDesc& g, const Vec3& lo, const Vec3& hi, int32_t res);

// Kernel views of the above (valid while the descs live).
SparseGridView sparse_grid_view(const SparseGridDesc& g);
MajorantGridView majorant_grid_view(const MajorantGridDesc& m);

}  // namespace tessera
