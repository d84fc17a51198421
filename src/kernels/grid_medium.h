// pbrt-v4's "uniformgrid" medium: a density grid over a box (in the
// medium's own space) scaling sigma_a, sigma_s and the emission. Collisions
// are found by delta tracking against one majorant (the grid's largest
// density times the largest extinction of the three channels), weighted so
// that every channel stays unbiased (spectral tracking, Kutz et al. 2017,
// with the channels' mean as probabilities); shadow rays use ratio tracking.
// The random numbers of a segment come from a PCG32 stream seeded by the
// pixel sampler and the ray, so a path still draws a fixed number of
// sampler dimensions per segment.
#pragma once

#include "medium.h"
#include "rng.h"

namespace tessera {

struct DensityGridView {
  Mat3 medium_from_world{1.f};  // linear part of the inverse of the CTM at MakeNamedMedium
  Vec3 medium_from_world_offset{0.f};
  Vec3 p0{0.f}, p1{1.f};        // the grid's box, medium space
  int32_t nx = 1, ny = 1, nz = 1;
  const Float* density = nullptr;  // nx * ny * nz, x fastest
  Float max_density = 0.f;
};

// pbrt-v4's SampledGrid lookup: samples at voxel centres, trilinear, zero outside.
TESSERA_HOST_DEVICE inline Float grid_density(const DensityGridView& g, const Vec3& p_medium) {
  const Vec3 u = (p_medium - g.p0) / (g.p1 - g.p0);
  const Float fx = u.x * g.nx - 0.5f, fy = u.y * g.ny - 0.5f, fz = u.z * g.nz - 0.5f;
  if (!(fx > -1.f && fy > -1.f && fz > -1.f && fx < g.nx && fy < g.ny && fz < g.nz)) return 0.f;
  const int32_t ix = static_cast<int32_t>(glm::floor(fx)), iy = static_cast<int32_t>(glm::floor(fy)),
                iz = static_cast<int32_t>(glm::floor(fz));
  const Float dx = fx - ix, dy = fy - iy, dz = fz - iz;
  auto at = [&](int32_t x, int32_t y, int32_t z) -> Float {
    if (x < 0 || y < 0 || z < 0 || x >= g.nx || y >= g.ny || z >= g.nz) return 0.f;
    return g.density[(static_cast<size_t>(z) * g.ny + y) * g.nx + x];
  };
  auto lerp = [](Float t, Float a, Float b) { return a + t * (b - a); };
  const Float d00 = lerp(dx, at(ix, iy, iz), at(ix + 1, iy, iz)), d10 = lerp(dx, at(ix, iy + 1, iz), at(ix + 1, iy + 1, iz));
  const Float d01 = lerp(dx, at(ix, iy, iz + 1), at(ix + 1, iy, iz + 1));
  const Float d11 = lerp(dx, at(ix, iy + 1, iz + 1), at(ix + 1, iy + 1, iz + 1));
  return lerp(dz, lerp(dy, d00, d10), lerp(dy, d01, d11));
}

// The part [t0, t1] of the segment o + t d, t in [0, t_max], inside the box.
struct GridRay {
  Vec3 o, d;  // medium space (d not unit: t stays the world-space distance)
  Float t0, t1;
};

TESSERA_HOST_DEVICE inline bool grid_clip(const DensityGridView& g, const Vec3& o, const Vec3& d, Float t_max,
                                          GridRay* r) {
  r->o = g.medium_from_world * o + g.medium_from_world_offset;
  r->d = g.medium_from_world * d;
  Float t0 = 0.f, t1 = t_max;
  for (int a = 0; a < 3; ++a) {
    const Float inv = 1.f / r->d[a];
    Float tn = (g.p0[a] - r->o[a]) * inv, tf = (g.p1[a] - r->o[a]) * inv;
    if (tn > tf) {
      const Float t = tn;
      tn = tf;
      tf = t;
    }
    // NaN (a zero direction component on a slab boundary) leaves the interval as it is.
    t0 = tn > t0 ? tn : t0;
    t1 = tf < t1 ? tf : t1;
    if (t0 > t1) return false;
  }
  r->t0 = t0;
  r->t1 = t1;
  return true;
}

// Largest extinction of any channel anywhere in the grid.
TESSERA_HOST_DEVICE inline Float grid_majorant(const Medium& m, const DensityGridView& g) {
  return g.max_density * max_component(medium_sigma_t(m));
}

// The stream of one segment's tracking numbers.
TESSERA_HOST_DEVICE inline Rng tracking_rng(Float u, const Vec3& o, const Vec3& d) {
  Rng r;
  r.set_sequence(hash_vec3(o) ^ (static_cast<uint64_t>(float_bits(u)) << 17), hash_vec3(d));
  return r;
}

// The next tentative collision along the clipped ray, against the majorant:
// false once past the box (or after 2^20 of them). t is double so that free
// paths far smaller than t still advance it.
TESSERA_HOST_DEVICE inline bool next_tentative_collision(const DensityGridView& g, const GridRay& r, Float majorant,
                                                         Rng& rng, int32_t& steps, double& t, Float& density) {
  if (++steps > (1 << 20)) return false;
  t += -glm::log(1.f - rng.uniform()) / majorant;
  if (!(t < r.t1)) return false;
  density = grid_density(g, r.o + static_cast<Float>(t) * r.d);
  return true;
}

// Delta tracking along [0, t_max]: a real collision (weight sigma_s / its
// probability) or the end of the segment; absorption ends the path (weight 0).
TESSERA_HOST_DEVICE inline MediumSegment sample_grid_segment(const Medium& m, const DensityGridView& g, const Vec3& o,
                                                             const Vec3& d, Float t_max, Float u) {
  MediumSegment seg;
  seg.t = t_max;
  GridRay r;
  const Float majorant = grid_majorant(m, g);
  if (!(majorant > 0.f) || !grid_clip(g, o, d, t_max, &r)) return seg;
  Rng rng = tracking_rng(u, o, d);
  Rgb w(1.f);
  double t = r.t0;
  int32_t steps = 0;
  Float dens = 0.f;
  while (next_tentative_collision(g, r, majorant, rng, steps, t, dens)) {
    const Rgb sigma_a = dens * m.sigma_a, sigma_s = dens * m.sigma_s;
    const Rgb sigma_n = Rgb(majorant) - sigma_a - sigma_s;
    seg.emitted += w * sigma_a * m.Le / majorant;
    const Float p_s = (sigma_s.x + sigma_s.y + sigma_s.z) / (3.f * majorant);
    const Float p_n = glm::max(0.f, (sigma_n.x + sigma_n.y + sigma_n.z) / (3.f * majorant));
    const Float e = rng.uniform();
    if (e < p_s) {
      seg.scattered = true;
      seg.t = static_cast<Float>(t);
      seg.weight = w * sigma_s / (majorant * p_s);
      return seg;
    }
    if (e < p_s + p_n) {
      w *= glm::max(sigma_n, Rgb(0.f)) / (majorant * p_n);
      continue;
    }
    seg.scattered = true;  // absorbed: the path ends here
    seg.t = static_cast<Float>(t);
    seg.weight = Rgb(0.f);
    return seg;
  }
  seg.weight = w;
  return seg;
}

// Ratio tracking: an unbiased estimate of the transmittance along [0, t_max].
TESSERA_HOST_DEVICE inline Rgb grid_transmittance(const Medium& m, const DensityGridView& g, const Vec3& o,
                                                  const Vec3& d, Float t_max) {
  GridRay r;
  const Float majorant = grid_majorant(m, g);
  if (!(majorant > 0.f) || !grid_clip(g, o, d, t_max, &r)) return Rgb(1.f);
  Rng rng = tracking_rng(0.5f, o, d);
  Rgb tr(1.f);
  double t = r.t0;
  int32_t steps = 0;
  Float dens = 0.f;
  while (next_tentative_collision(g, r, majorant, rng, steps, t, dens)) {
    tr *= glm::max(Rgb(0.f), Rgb(1.f) - dens * medium_sigma_t(m) / majorant);
    // Russian roulette once little is left (unbiased: survivors are scaled up).
    const Float left = max_component(tr);
    if (left < 0.05f) {
      if (rng.uniform() < 0.5f) return Rgb(0.f);
      tr *= 2.f;
    }
  }
  return tr;
}

}  // namespace tessera
