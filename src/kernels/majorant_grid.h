// A coarse grid of density bounds over a grid medium's box, walked cell by
// cell along a ray (a 3D DDA, Amanatides & Woo 1987), as pbrt-v4's
// MajorantGrid and DDAMajorantIterator do: delta and ratio tracking then
// take steps against the bound of the cell they are in, so the empty parts
// of a sparse cloud cost one cell crossing instead of many null collisions.
#pragma once

#include "vecmath.h"

namespace tessera {

struct MajorantGridView {
  Vec3 lo{0.f}, hi{1.f};          // the box it covers (the density grid's lattice coordinates)
  int32_t nx = 1, ny = 1, nz = 1;  // cells per axis
  const Float* max_density = nullptr;  // per cell, x fastest: no density inside the cell exceeds it
};

// The walk of one ray (in the box's coordinates, t the caller's parameter)
// through the cells it crosses, in order.
struct MajorantWalk {
  int32_t cell[3];
  int32_t step[3];
  Float t_next[3];  // t at which the ray leaves the current cell along each axis
  Float dt[3];      // t to cross one cell along each axis
  Float t, t_end;
  int32_t crossings;
};

// Starts the walk on [t0, t1] (already clipped to the box).
TESSERA_HOST_DEVICE inline MajorantWalk majorant_walk(const MajorantGridView& g, const Vec3& o, const Vec3& d,
                                                      Float t0, Float t1) {
  MajorantWalk w;
  w.t = t0;
  w.t_end = t1;
  w.crossings = 0;
  const int32_t res[3] = {g.nx, g.ny, g.nz};
  for (int a = 0; a < 3; ++a) {
    const Float scale = res[a] / (g.hi[a] - g.lo[a]);  // cells per unit
    const Float p = (o[a] + t0 * d[a] - g.lo[a]) * scale;
    const Float dc = d[a] * scale;                      // cells per unit of t
    w.cell[a] = glm::clamp(static_cast<int32_t>(glm::floor(p)), 0, res[a] - 1);
    if (dc > 0.f) {
      w.step[a] = 1;
      w.dt[a] = 1.f / dc;
      w.t_next[a] = t0 + (w.cell[a] + 1 - p) / dc;
    } else if (dc < 0.f) {
      w.step[a] = -1;
      w.dt[a] = -1.f / dc;
      w.t_next[a] = t0 + (w.cell[a] - p) / dc;
    } else {
      w.step[a] = 0;
      w.dt[a] = kInfinity;
      w.t_next[a] = kInfinity;
    }
  }
  return w;
}

// The next cell's part of the ray, [*ta, *tb], and its density bound; false
// once the walk has left the box or passed t_end.
TESSERA_HOST_DEVICE inline bool majorant_next(const MajorantGridView& g, MajorantWalk& w, Float* ta, Float* tb,
                                              Float* max_density) {
  // Every crossing moves one cell; more than the cells along a diagonal
  // means the numbers went wrong (NaN): stop rather than loop.
  if (!(w.t < w.t_end) || ++w.crossings > g.nx + g.ny + g.nz + 3) return false;
  const int a = w.t_next[0] < w.t_next[1] ? (w.t_next[0] < w.t_next[2] ? 0 : 2) : (w.t_next[1] < w.t_next[2] ? 1 : 2);
  *ta = w.t;
  *tb = glm::max(w.t, glm::min(w.t_next[a], w.t_end));  // rounding never runs t backwards
  *max_density = g.max_density[(static_cast<size_t>(w.cell[2]) * g.ny + w.cell[1]) * g.nx + w.cell[0]];
  w.t = *tb;
  w.cell[a] += w.step[a];
  w.t_next[a] += w.dt[a];
  const int32_t res[3] = {g.nx, g.ny, g.nz};
  if (w.cell[a] < 0 || w.cell[a] >= res[a]) w.t_end = w.t;  // left the box: this was the last cell
  return true;
}

}  // namespace tessera
