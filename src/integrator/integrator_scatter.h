// Scattering at a surface vertex: the direction from the BSDF or, at guided
// vertices, from the mixture of the BSDF and the guide (weighted by the
// mixture pdf, which also stands in for the BSDF pdf in every MIS weight:
// the estimator stays unbiased whatever the guide has learned); the path's
// state after it; and Russian roulette, after surfaces and media alike.
#pragma once

#include "integrator/integrator_surface.h"

namespace tessera {

// The direction a vertex took and its densities.
struct ScatterSample {
  BsdfSample bs;               // in the shading frame; bs.pdf is the BSDF's
  Vec3 wi;                     // world space
  Float pdf = 0.f;             // the density it was drawn with (the mixture's where guided)
  Float bsdf_pdf = 0.f;        // the BSDF's own density of it (for roulette)
  uint32_t bin = 0;            // its guide bin (guiding only)
  Float guide_density = 0.f;   // the guide's density of it (guided vertices only)
};

// Draws the vertex's direction with (uc, u); guide_p > 0: from the guide
// with that probability (one more dimension picks the strategy). False: the
// path ends (no direction).
template <class Ctx>
TESSERA_HOST_DEVICE TESSERA_INLINE bool sample_scatter(Ctx& x, const PathState& st, const SurfaceVertex& v, Float guide_p,
                                               Float uc, Vec2 u, ScatterSample* out) {
  constexpr uint32_t Spec = Ctx::kSpec;
  ScatterSample& r = *out;
  BsdfSample& bs = r.bs;
  if (guide_p > 0.f) {
    ++x.c.guidable_vertices;
    const Float p = guide_p;
    if (x.rng.uniform() < p) {
      ++x.c.guided_samples;
      if (!x.guide.sample(v.cell, uc, u, &r.wi, &r.guide_density, &r.bin)) return false;
      bs.wi = v.frame.to_local(r.wi);
      bs.f = eval_f<Spec>(v.bsdf, v.wo_l, bs.wi);
      const bool transmit = !same_hemisphere(v.wo_l, bs.wi);
      bs.lobe = transmit ? kLobeTransmission : kLobeReflection;
      bs.eta = transmit ? (v.wo_l.z > 0.f ? v.bsdf.ior : 1.f / v.bsdf.ior) : 1.f;
      r.bsdf_pdf = eval_pdf<Spec>(v.bsdf, v.wo_l, bs.wi);
      r.pdf = p * r.guide_density + (1.f - p) * r.bsdf_pdf;
    } else {
      if (!sample_f<Spec>(v.bsdf, v.wo_l, uc, u, &bs) || !(bs.pdf > 0.f)) return false;
      r.wi = v.frame.to_world(bs.wi);
      r.bsdf_pdf = bs.pdf;
      r.bin = x.guide.bin_of(r.wi);
      r.guide_density = x.guide.bin_pdf(v.cell, r.bin);
      r.pdf = p * r.guide_density + (1.f - p) * bs.pdf;
    }
  } else {
    if (!sample_f<Spec>(v.bsdf, v.wo_l, uc, u, &bs) || !(bs.pdf > 0.f)) return false;
    r.wi = v.frame.to_world(bs.wi);
    r.pdf = r.bsdf_pdf = bs.pdf;
    if (x.learn || (st.path_expected > 0.f && x.guide.learned(v.cell))) r.bin = x.guide.bin_of(r.wi);
  }
  return r.pdf > 0.f;
}

// The path after taking direction r at vertex v: throughputs, the MIS
// memory, the flags light-traced caustics read, the next ray and medium.
template <class Ctx>
TESSERA_HOST_DEVICE TESSERA_INLINE void move_past_surface(Ctx& x, PathState& st, const SurfaceVertex& v, const ScatterSample& r,
                                                  const Rgb& weight, Float guide_p) {
  constexpr uint32_t Spec = Ctx::kSpec;
  const BsdfSample& bs = r.bs;
  st.beta *= weight;
  st.rr_beta *= r.bsdf_pdf > 0.f ? bs.f * (abs_cos_theta(bs.wi) / r.bsdf_pdf) : weight;
  if (guide_p > 0.f) st.guide_ratio *= r.bsdf_pdf / r.pdf;
  st.mis.balance = mis_balance<Spec>(x.s, v.bsdf);
  st.mis.pdf = r.pdf;
  st.mis.pending = false;
  if constexpr ((Spec & kSpecNonDiffuse) != 0) {
    if (bsdf_mis_estimated(v.bsdf) && !(bs.lobe & kLobeSpecular)) {  // a specular direction is not weighed
      st.mis.bsdf = v.bsdf;
      st.mis.wo = v.wo_l;
      st.mis.wi = bs.wi;
      st.mis.guide_p = guide_p;
      st.mis.guide_density = r.guide_density;
      st.mis.pending = true;
    }
  }
  st.mis.cell = v.cell;
  st.specular_bounce = (bs.lobe & kLobeSpecular) != 0;
  if (st.depth == 1) st.first_vertex_connectable = x.settings.light_traced_caustics && !st.specular_bounce;
  st.last_vertex_delta_only = !lobes_have_non_specular(v.lobes);
  if (bs.lobe & kLobeTransmission) st.eta_scale *= sqr(bs.eta);
  Vec3 wi = r.wi;
  if (keeps_lobe_side(v.bsdf, bs.lobe)) wi = keep_on_lobe_side(wi, v.wo, v.h.ng, (bs.lobe & kLobeTransmission) != 0);
  st.ray.o = offset_ray_origin(v.h, wi);
  st.ray.d = wi;
  st.mis.p = v.h.p;
  st.mis.n = v.h.ns;
  st.mis.in_medium = false;
  if constexpr (Ctx::kMedia) st.medium = medium_after(x.s, v.h.triangle, v.h.ng, wi, st.medium);
}

// Russian roulette after the second bounce: pbrt-v4's rule, on throughput
// corrected for radiance scaling at refractive boundaries; where the guide
// has learned and predicted this path's radiance, a path it expects to
// bring light along bin `bin` of vertex `cell` survives more often (cell
// -1: a medium vertex, the throughput rule alone). False: the path ends.
template <class Ctx>
TESSERA_HOST_DEVICE TESSERA_INLINE bool survives_roulette(Ctx& x, PathState& st, int32_t cell, uint32_t bin) {
  if (st.depth > 1) {
    Float survive = glm::min(1.f, max_component(st.rr_beta * st.eta_scale));
    if (Ctx::kGuide && cell >= 0 && st.path_expected > 0.f && x.guide.learned(cell)) {
      survive = glm::max(survive, x.guide.survival(cell, bin, luminance(st.beta), st.path_expected,
                                                   x.settings.guided_roulette_window));
      ++x.c.guided_roulette;
    }
    if (survive < 1.f) {
      if (x.rng.uniform() < 1.f - survive) return false;
      st.beta /= survive;
      st.rr_beta /= survive;
    }
  }
  return !is_black(st.beta);
}

}  // namespace tessera
