#include "scene/sparse_grid_build.h"

#include <algorithm>
#include <cmath>

namespace tessera {

SparseGridBuilder::SparseGridBuilder(int32_t nx, int32_t ny, int32_t nz, Float background) {
  g_.background = background;
  g_.max_value = background;
  g_.nx = nx;
  g_.ny = ny;
  g_.nz = nz;
  g_.bx = (nx + kBrickSide - 1) / kBrickSide;
  g_.by = (ny + kBrickSide - 1) / kBrickSide;
  g_.bz = (nz + kBrickSide - 1) / kBrickSide;
  g_.brick_of.assign(static_cast<size_t>(g_.bx) * g_.by * g_.bz, -1);
}

int32_t SparseGridBuilder::new_brick(Float fill) {
  const int32_t index = static_cast<int32_t>(g_.values.size() / kBrickVoxels);
  g_.values.resize(g_.values.size() + kBrickVoxels, fill);
  shared_.push_back(0);
  return index;
}

void SparseGridBuilder::set(int32_t x, int32_t y, int32_t z, Float v) {
  const size_t b = (static_cast<size_t>(z >> kBrickLog2) * g_.by + (y >> kBrickLog2)) * g_.bx + (x >> kBrickLog2);
  int32_t brick = g_.brick_of[b];
  if (brick < 0) {
    if (v == g_.background) return;
    brick = g_.brick_of[b] = new_brick(g_.background);
  } else if (shared_[static_cast<size_t>(brick)]) {
    const int32_t copy = new_brick(0.f);
    std::copy_n(g_.values.begin() + static_cast<ptrdiff_t>(brick) * kBrickVoxels, kBrickVoxels,
                g_.values.begin() + static_cast<ptrdiff_t>(copy) * kBrickVoxels);
    brick = g_.brick_of[b] = copy;
  }
  const int32_t m = kBrickSide - 1;
  g_.values[static_cast<size_t>(brick) * kBrickVoxels + (((z & m) * kBrickSide + (y & m)) * kBrickSide + (x & m))] = v;
  g_.max_value = std::max(g_.max_value, v);
}

void SparseGridBuilder::fill_brick(int32_t bx, int32_t by, int32_t bz, Float v) {
  const size_t b = (static_cast<size_t>(bz) * g_.by + by) * g_.bx + bx;
  if (v == g_.background) {
    g_.brick_of[b] = -1;
    return;
  }
  // One brick per distinct value, the most recent one kept (tiles of one value come together).
  if (shared_brick_ < 0 || g_.values[static_cast<size_t>(shared_brick_) * kBrickVoxels] != v) {
    shared_brick_ = new_brick(v);
    shared_[static_cast<size_t>(shared_brick_)] = 1;
  }
  g_.brick_of[b] = shared_brick_;
  g_.max_value = std::max(g_.max_value, v);
}

SparseGridDesc SparseGridBuilder::finish(const Mat4& lattice_from_world) {
  g_.lattice_from_world = lattice_from_world;
  return std::move(g_);
}

SparseGridDesc sparse_grid_from_dense(const std::vector<Float>& values, int32_t nx, int32_t ny, int32_t nz,
                                      const Vec3& p0, const Vec3& p1, const Mat4& medium_from_world) {
  SparseGridBuilder b(nx, ny, nz);
  size_t i = 0;
  for (int32_t z = 0; z < nz; ++z)
    for (int32_t y = 0; y < ny; ++y)
      for (int32_t x = 0; x < nx; ++x) b.set(x, y, z, values[i++]);
  // Voxel centre (x + 0.5) / n of the box is lattice point x.
  const Vec3 n(static_cast<Float>(nx), static_cast<Float>(ny), static_cast<Float>(nz));
  const Vec3 s = n / (p1 - p0);
  Mat4 lattice_from_medium(1.f);
  for (int a = 0; a < 3; ++a) {
    lattice_from_medium[a][a] = s[a];
    lattice_from_medium[3][a] = -p0[a] * s[a] - 0.5f;
  }
  return b.finish(lattice_from_medium * medium_from_world);
}

MajorantGridDesc build_majorant_grid(const SparseGridDesc& g, const Vec3& lo, const Vec3& hi, int32_t res) {
  MajorantGridDesc m;
  m.lo = lo;
  m.hi = hi;
  m.nx = m.ny = m.nz = res;
  m.max_density.assign(static_cast<size_t>(res) * res * res, 0.f);
  // Lattice point q reaches the lookups at (q - 1, q + 1): the cells [first, last] overlapping that range.
  double cells_per_unit[3];
  for (int a = 0; a < 3; ++a) cells_per_unit[a] = res / (static_cast<double>(hi[a]) - lo[a]);
  auto cell = [&](int a, double x) {
    const double c = std::floor((x - lo[a]) * cells_per_unit[a]);
    return c < 0.0 ? 0 : c > res - 1 ? res - 1 : static_cast<int32_t>(c);
  };
  const int32_t mask = kBrickSide - 1;
  for (int32_t bz = 0; bz < g.bz; ++bz)
    for (int32_t by = 0; by < g.by; ++by)
      for (int32_t bx = 0; bx < g.bx; ++bx) {
        const int32_t brick = g.brick_of[(static_cast<size_t>(bz) * g.by + by) * g.bx + bx];
        if (brick < 0) continue;
        const Float* v = g.values.data() + static_cast<size_t>(brick) * kBrickVoxels;
        for (int32_t i = 0; i < kBrickVoxels; ++i) {
          if (!(v[i] > 0.f)) continue;
          const int32_t x = bx * kBrickSide + (i & mask), y = by * kBrickSide + ((i >> kBrickLog2) & mask),
                        z = bz * kBrickSide + (i >> (2 * kBrickLog2));
          if (x >= g.nx || y >= g.ny || z >= g.nz) continue;
          for (int32_t cz = cell(2, z - 1.0); cz <= cell(2, z + 1.0); ++cz)
            for (int32_t cy = cell(1, y - 1.0); cy <= cell(1, y + 1.0); ++cy)
              for (int32_t cx = cell(0, x - 1.0); cx <= cell(0, x + 1.0); ++cx) {
                Float& c = m.max_density[(static_cast<size_t>(cz) * res + cy) * res + cx];
                c = std::max(c, v[i]);
              }
        }
      }
  return m;
}

SparseGridView sparse_grid_view(const SparseGridDesc& g) {
  SparseGridView v;
  v.lattice_from_world = Mat3(g.lattice_from_world);
  v.lattice_from_world_offset = Vec3(g.lattice_from_world[3]);
  v.nx = g.nx;
  v.ny = g.ny;
  v.nz = g.nz;
  v.bx = g.bx;
  v.by = g.by;
  v.bz = g.bz;
  v.brick_of = g.brick_of.empty() ? nullptr : g.brick_of.data();
  v.values = g.values.empty() ? nullptr : g.values.data();
  v.background = g.background;
  return v;
}

MajorantGridView majorant_grid_view(const MajorantGridDesc& m) {
  MajorantGridView v;
  v.lo = m.lo;
  v.hi = m.hi;
  v.nx = m.nx;
  v.ny = m.ny;
  v.nz = m.nz;
  v.max_density = m.max_density.data();
  return v;
}

}  // namespace tessera
