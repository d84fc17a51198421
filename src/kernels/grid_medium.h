// pbrt-v4's grid media ("uniformgrid", "nanovdb", and the procedural
// "cloud"): a density lattice (sparse_grid.h) or function scaling sigma_a,
// sigma_s and the emission inside a box.
// Collisions are found by delta tracking against the majorant of the
// majorant-grid cell they fall in (its largest density times the largest
// extinction of the three channels), the events chosen with the path's hero
// channel and weighted by the hero MIS of medium.h (spectral tracking, Kutz
// et al. 2017, made path-level as pbrt-v4 does); shadow rays use ratio tracking.
// The random numbers of a segment come from a PCG32 stream seeded by the
// pixel sampler and the ray, so a path still draws a fixed number of
// sampler dimensions per segment.
#pragma once

#include "blackbody_table.h"
#include "majorant_grid.h"
#include "medium.h"
#include "perlin_noise.h"
#include "rgb_grid.h"
#include "rng.h"
#include "sparse_grid.h"
#include "spectral.h"

namespace tessera {

// One grid medium: its density lattice, the majorant grid over its box and
// what makes it glow.
struct GridMediumView {
  SparseGridView density;
  MajorantGridView majorants;  // over the medium's box, in density lattice coordinates
  // Emission per unit absorption, as pbrt-v4's GridMedium and NanoVDBMedium
  // give it: le_scale(p) times Medium::Le, or, with a temperature grid,
  // le_scale(p) * blackbody_scale * B(T) / B(peak) for T = (temperature(p) -
  // offset) * scale above 100 K.
  SparseGridView le_scale;     // absent: 1
  SparseGridView temperature;  // absent: Medium::Le
  Float temperature_offset = 0.f, temperature_scale = 1.f, blackbody_scale = 1.f;
  const Float* blackbody_rgb = nullptr;  // RGB transport: kBlackbodyTableSize RGB triples (blackbody_table.h)
  // pbrt-v4's "cloud": a procedural density instead of the lattice, whose
  // lattice_from_world is then the medium's space.
  int32_t cloud = 0;
  Float cloud_density = 1.f, cloud_wispiness = 1.f, cloud_frequency = 5.f;
  // pbrt-v4's "rgbgrid": per-voxel coefficients on the density lattice's
  // coordinates (which then holds no values), scaled by rgb_scale; a grid
  // not given is 1 everywhere (Le: 0). Its majorant cells hold the whole
  // extinction bound.
  int32_t rgb = 0;
  RgbGridView rgb_sigma_a, rgb_sigma_s, rgb_le;
  Float rgb_scale = 1.f, rgb_le_scale = 1.f;
  const SpectralView* spectral = nullptr;  // spectral transport's tables (rgb grids convert per voxel)
};

// pbrt-v4's CloudMedium density at p (medium space): five octaves of noise
// at `frequency`, displaced by two octaves of its gradient (`wispiness`),
// thinning with height and clamped to [0, 1], with a solid base below y = 0.5.
TESSERA_HOST_DEVICE inline Float cloud_density(const GridMediumView& g, const Vec3& p) {
  Vec3 pp = g.cloud_frequency * p;
  if (g.cloud_wispiness > 0.f) {
    Float omega = 0.05f * g.cloud_wispiness, lambda = 10.f;
    for (int i = 0; i < 2; ++i) {
      pp += omega * perlin_noise_gradient(lambda * pp);
      omega *= 0.5f;
      lambda *= 1.99f;
    }
  }
  Float d = 0.f, omega = 0.5f, lambda = 1.f;
  for (int i = 0; i < 5; ++i) {
    d += omega * perlin_noise(lambda * pp);
    omega *= 0.5f;
    lambda *= 1.99f;
  }
  d = glm::clamp((1.f - p.y) * 4.5f * g.cloud_density * d, 0.f, 1.f);
  d += 2.f * glm::max(0.f, 0.5f - p.y);
  return glm::clamp(d, 0.f, 1.f);
}

// Density at q, the density lattice's coordinates (the medium's space for a cloud).
TESSERA_HOST_DEVICE inline Float density_at(const GridMediumView& g, const Vec3& q) {
  return g.cloud ? cloud_density(g, q) : lattice_trilinear(g.density, q);
}

TESSERA_HOST_DEVICE inline Float grid_density(const GridMediumView& g, const Vec3& p_world) {
  return density_at(g, grid_lattice_point(g.density, p_world));
}

// sigma_a and sigma_s at q (lattice coordinates) at the path's wavelengths
// (wl) or in RGB; m is the medium as the path sees it (medium_at).
TESSERA_HOST_DEVICE inline void grid_coefficients(const GridMediumView& g, const Medium& m, const Vec3& q,
                                                  const Wavelengths* wl, Rgb* sigma_a, Rgb* sigma_s) {
  if (g.rgb) {
    *sigma_a = rgb_grid_present(g.rgb_sigma_a) ? g.rgb_scale * rgb_grid_value(g.rgb_sigma_a, q, g.spectral, wl, false)
                                               : Rgb(g.rgb_scale);
    *sigma_s = rgb_grid_present(g.rgb_sigma_s) ? g.rgb_scale * rgb_grid_value(g.rgb_sigma_s, q, g.spectral, wl, false)
                                               : Rgb(g.rgb_scale);
    return;
  }
  const Float d = density_at(g, q);
  *sigma_a = d * m.sigma_a;
  *sigma_s = d * m.sigma_s;
}

// What the majorant cells are multiplied by: the medium's largest
// extinction per unit density (rgb grids store the whole bound).
TESSERA_HOST_DEVICE inline Float grid_extinction_scale(const GridMediumView& g, const Medium& m) {
  return g.rgb ? 1.f : max_component(medium_sigma_t(m));
}

// Emitted radiance per unit absorption at p (world), at the path's
// wavelengths (wl) or in RGB. m is the medium as the path sees it (medium_at).
TESSERA_HOST_DEVICE inline Rgb grid_emission(const GridMediumView& g, const Medium& m, const Vec3& p,
                                             const Wavelengths* wl) {
  if (g.rgb)
    return rgb_grid_present(g.rgb_le)
               ? g.rgb_le_scale * rgb_grid_value(g.rgb_le, grid_lattice_point(g.density, p), g.spectral, wl, true)
               : Rgb(0.f);
  const Float s = grid_present(g.le_scale) ? grid_value(g.le_scale, p) : 1.f;
  if (!(s > 0.f)) return Rgb(0.f);
  if (!grid_present(g.temperature)) return s * m.Le;
  const Float kelvin = (grid_value(g.temperature, p) - g.temperature_offset) * g.temperature_scale;
  if (!(kelvin > 100.f)) return Rgb(0.f);
  const Float k = s * g.blackbody_scale;
  if (wl)
    return k * Rgb(blackbody_relative(wl->lambda[0], kelvin), blackbody_relative(wl->lambda[1], kelvin),
                   blackbody_relative(wl->lambda[2], kelvin));
  return k * blackbody_table_rgb(g.blackbody_rgb, kelvin);
}

// The part [t0, t1] of the segment o + t d, t in [0, t_max], inside the
// medium's box, in density lattice coordinates (d not unit: t stays the
// world-space distance).
struct GridRay {
  Vec3 o, d;
  Float t0, t1;
};

TESSERA_HOST_DEVICE inline bool grid_clip(const GridMediumView& g, const Vec3& o, const Vec3& d, Float t_max,
                                          GridRay* r) {
  r->o = grid_lattice_point(g.density, o);
  r->d = g.density.lattice_from_world * d;
  Float t0 = 0.f, t1 = t_max;
  for (int a = 0; a < 3; ++a) {
    const Float inv = 1.f / r->d[a];
    Float tn = (g.majorants.lo[a] - r->o[a]) * inv, tf = (g.majorants.hi[a] - r->o[a]) * inv;
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

// The stream of one segment's tracking numbers.
TESSERA_HOST_DEVICE inline Rng tracking_rng(Float u, const Vec3& o, const Vec3& d) {
  Rng r;
  r.set_sequence(hash_vec3(o) ^ (static_cast<uint64_t>(float_bits(u)) << 17), hash_vec3(d));
  return r;
}

// The tentative collisions along a clipped ray, each sampled against the
// majorant of the cell it falls in (an exponential step that crosses into
// the next cell restarts there: free paths are memoryless).
struct TentativeCollisions {
  GridRay r;
  MajorantWalk walk;
  Float sigma_t_max;  // the medium's largest extinction coefficient (per unit density)
  Float tb = 0.f;     // end of the current cell's part
  Float majorant = 0.f;
  double t = 0.0;     // double so that free paths far smaller than t still advance it
  int32_t steps = 0;
  bool in_cell = false;
};

TESSERA_HOST_DEVICE inline TentativeCollisions tentative_collisions(const GridMediumView& g, const GridRay& r,
                                                                    Float sigma_t_max) {
  TentativeCollisions c;
  c.r = r;
  c.walk = majorant_walk(g.majorants, r.o, r.d, r.t0, r.t1);
  c.sigma_t_max = sigma_t_max;
  return c;
}

// The next tentative collision (c.t, its lattice point q, c.majorant);
// false once past the box (or after 2^20 of them).
TESSERA_HOST_DEVICE inline bool next_tentative_collision(const GridMediumView& g, TentativeCollisions& c, Rng& rng,
                                                         Vec3& q) {
  for (;;) {
    if (!c.in_cell) {
      Float ta, cell_max;
      if (!majorant_next(g.majorants, c.walk, &ta, &c.tb, &cell_max)) return false;
      c.majorant = cell_max * c.sigma_t_max;
      if (!(c.majorant > 0.f)) continue;
      c.t = ta;
      c.in_cell = true;
    }
    if (++c.steps > (1 << 20)) return false;
    c.t += -glm::log(1.f - rng.uniform()) / c.majorant;
    if (!(c.t < c.tb)) {
      c.in_cell = false;
      continue;
    }
    q = c.r.o + static_cast<Float>(c.t) * c.r.d;
    return true;
  }
}

// Delta tracking along [0, t_max] with the hero's collision probabilities
// (scatter sigma_s / majorant, null the rest of the majorant, absorb
// sigma_a), each channel weighted by hero_event: a real collision, or the end
// of the segment; absorption ends the path (weight 0).
TESSERA_HOST_DEVICE inline MediumSegment sample_grid_segment(const Medium& m, const GridMediumView& g, const Vec3& o,
                                                             const Vec3& d, Float t_max, Float u,
                                                             const Wavelengths* wl, HeroChannels& h) {
  const bool emits = m.grid_emits || !is_black(m.Le);
  MediumSegment seg;
  seg.t = t_max;
  GridRay r;
  const Float sigma_t_max = grid_extinction_scale(g, m);
  if (!(sigma_t_max > 0.f) || !grid_clip(g, o, d, t_max, &r)) return seg;
  Rng rng = tracking_rng(u, o, d);
  TentativeCollisions c = tentative_collisions(g, r, sigma_t_max);
  Rgb w(1.f);
  Vec3 q;
  while (next_tentative_collision(g, c, rng, q)) {
    const Float majorant = c.majorant;
    Rgb sigma_a, sigma_s;
    grid_coefficients(g, m, q, wl, &sigma_a, &sigma_s);
    const Rgb sigma_n = glm::max(Rgb(majorant) - sigma_a - sigma_s, Rgb(0.f));
    if (emits && !is_black(sigma_a))
      seg.emitted += w * sigma_a * grid_emission(g, m, o + static_cast<Float>(c.t) * d, wl) / majorant;
    const Float p_s = sigma_s[h.hero] / majorant, p_n = sigma_n[h.hero] / majorant;
    const Float e = rng.uniform();
    if (e < p_s) {
      seg.scattered = true;
      seg.t = static_cast<Float>(c.t);
      seg.weight = w * (hero_event(h, sigma_s) * sigma_s);
      return seg;
    }
    if (e < p_s + p_n) {
      w *= hero_event(h, sigma_n) * sigma_n;
      if (is_black(w)) break;
      continue;
    }
    seg.scattered = true;  // absorbed: the path ends here
    seg.t = static_cast<Float>(c.t);
    seg.weight = Rgb(0.f);
    return seg;
  }
  seg.weight = w;
  return seg;
}

// Ratio tracking: an unbiased estimate of the transmittance along [0, t_max].
TESSERA_HOST_DEVICE inline Rgb grid_transmittance(const Medium& m, const GridMediumView& g, const Vec3& o,
                                                  const Vec3& d, Float t_max, const Wavelengths* wl) {
  GridRay r;
  const Float sigma_t_max = grid_extinction_scale(g, m);
  if (!(sigma_t_max > 0.f) || !grid_clip(g, o, d, t_max, &r)) return Rgb(1.f);
  Rng rng = tracking_rng(0.5f, o, d);
  TentativeCollisions c = tentative_collisions(g, r, sigma_t_max);
  Rgb tr(1.f);
  Vec3 q;
  while (next_tentative_collision(g, c, rng, q)) {
    Rgb sigma_a, sigma_s;
    grid_coefficients(g, m, q, wl, &sigma_a, &sigma_s);
    tr *= glm::max(Rgb(0.f), Rgb(1.f) - (sigma_a + sigma_s) / c.majorant);
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
