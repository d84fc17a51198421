// The surface-interaction stage: what the path found where its ray hit a
// surface (emission, the material's BSDF in its shading frame, the guide's
// vertex), and the vertex's estimate for the guide (its targets and the
// path's predicted radiance).
#pragma once

#include "integrator/integrator_emission.h"
#include "kernels/material_eval.h"
#include "kernels/volume_transport.h"

namespace tessera {

// The hit and the BSDF are the caller's: their addresses go to out-of-line
// code (the material, the general BSDF), and a vertex holding them would
// have to live in memory as a whole; apart, the rest stays in registers.
struct SurfaceVertex {
  TESSERA_HOST_DEVICE SurfaceVertex(SurfaceHit& hit, BsdfParams& b) : h(hit), bsdf(b) {}
  SurfaceHit& h;
  BsdfParams& bsdf;
  Vec3 wo;         // towards the previous vertex, world space
  Vec3 wo_l;       // ... in the shading frame
  Frame frame;
  uint32_t lobes = 0;
  bool delta_lobe = false;  // a specular lobe: no guiding here
  int32_t cell = -1;        // the guide's handle of the vertex (-1: none)
};

enum class SurfaceStep {
  kScatter,  // a vertex that scatters: direct light, then a direction
  kPass,     // an interface: the ray goes on through it, no bounce counted
  kEnd,      // the path ends here
};

// Interaction at the surface the ray hit: emission found there, the BSDF,
// the guide's vertex; counts the bounce (pbrt-v4's depth).
template <class Ctx>
TESSERA_HOST_DEVICE TESSERA_INLINE SurfaceStep surface_interaction(Ctx& x, PathState& st, const TraceHit& hit, SurfaceVertex* out) {
  constexpr uint32_t Spec = Ctx::kSpec;
  SurfaceVertex& v = *out;
  ++x.c.vertices;
  const RayPoint from_ray{st.ray.o, st.ray.d, hit.t};
  v.h = make_surface_hit(x.s, hit, st.ray.time, &from_ray);
  const Vec3 wo = -st.ray.d;  // (a copy goes to the out-of-line material code, not v's address)
  v.wo = wo;
  const TriangleInfo& info = x.s.triangles[hit.triangle];

  Rgb Le_hit(0.f);  // radiance emitted at this vertex towards the previous one
  if constexpr ((Spec & kSpecAreaLights) != 0)
    if (info.light >= 0) Le_hit = add_area_emission(x, st, v.h, v.wo, info.light);

  const int32_t single_before = st.wl ? st.wl->single : -1;
  if (!resolve_bsdf<Spec>(x.s, info.material, v.h, wo, &v.bsdf, st.wl)) {
    // Interface: continue through without counting a bounce (pbrt's SkipIntersection).
    ++x.c.interface_skips;
    if (++st.interface_skips > 256) return SurfaceStep::kEnd;
    if constexpr (Ctx::kMedia) st.medium = medium_after(x.s, hit.triangle, v.h.ng, st.ray.d, st.medium);
    st.ray.o = offset_ray_origin(v.h, st.ray.d);
    return SurfaceStep::kPass;
  }
  if (st.wl && st.wl->single != single_before) {
    // The path's first dispersive surface: from here on it carries one
    // wavelength, for all three (spectral.h).
    const Rgb mask = dispersion_mask(st.wl->single);
    st.beta *= mask;
    st.rr_beta *= mask;
    if constexpr (Ctx::kMedia) keep_only_channel(st.heroes, st.wl->single);
  }

  v.frame = shading_frame<Spec>(x.s, v.bsdf, v.h);
  v.wo_l = v.frame.to_local(v.wo);
  v.lobes = lobes_of<Spec>(v.bsdf);
  v.delta_lobe = (v.lobes & kLobeSpecular) != 0;

  v.cell = -1;
  if (x.guide.locates(st.depth, x.settings.max_depth)) {
    // The side the path is on: the two faces of a wall never share a cell.
    const Vec3 n_side = glm::dot(v.h.ng, v.wo) >= 0.f ? v.h.ng : -v.h.ng;
    v.cell = x.guide.locate(v.h.p, n_side);
    if (x.guide.reused_site()) ++x.c.neural_sites_reused;
    if (x.learn)
      learning_at_surface(x.guide, v.cell, n_side, (st.specular_bounce || !x.settings.nee) ? luminance(Le_hit) : 0.f,
                          v.delta_lobe);
  }

  // A path ending here leaves its last target unfinished (no NEE at y): dropped.
  if (st.depth++ == x.settings.max_depth) return SurfaceStep::kEnd;
  if (v.wo_l.z == 0.f) return SurfaceStep::kEnd;
  return SurfaceStep::kScatter;
}

// Probability of drawing the vertex's direction from the guide (0: the
// BSDF only); not once guiding has raised the path's weight
// max_guide_ratio-fold (PathState::guide_ratio).
template <class Ctx>
TESSERA_HOST_DEVICE TESSERA_INLINE Float vertex_guide_probability(Ctx& x, const PathState& st, const SurfaceVertex& v) {
  if (v.delta_lobe) return 0.f;
  Float guide_p = x.guide.probability(v.cell, v.bsdf, !Ctx::kNonDiffuse);
  if (guide_p > 0.f && !(st.guide_ratio <= x.settings.max_guide_ratio)) {
    guide_p = 0.f;
    ++x.c.guide_withheld_vertices;
  }
  return guide_p;
}

// guide_vertex_estimate's work where the vertex has any: out of line on the
// GPU (learning paths, and a path's first learned vertex under guided
// roulette).
template <class Ctx>
TESSERA_HOST_DEVICE TESSERA_COLD_STAGE void guide_vertex_estimate_at(Ctx& x, PathState& st, const SurfaceVertex& v,
                                                                     Float direct, bool completes_target,
                                                                     bool sets_expectation, bool records_nee) {
  const PendingTarget& pending = x.guide.pending;
  const bool lambertian = !Ctx::kNonDiffuse || v.bsdf.type == BsdfType::Diffuse;
  GuideBootstrap boot;
  const Frame frame = v.frame;  // not the vertex: its address would leave the stage
  const Float indirect = x.guide.bins_integral(v.cell, v.bsdf, lambertian, v.wo_l,
                                               [&frame](const Vec3& w) { return frame.to_local(w); }, x.rng, &boot);
  const Float reflected = direct + indirect;
  // The two shares of the light reflected here, for nee_prob.
  if (records_nee) x.guide.record_nee(v.cell, direct, indirect);
  if (completes_target) {
    learning_commit(x.guide, pending.le + reflected, boot, st.segment_tr, x.c.guide_updates);
    x.guide.pending.cell = -1;
  }
  if (sets_expectation) st.path_expected = luminance(st.beta) * reflected;
}

// Radiance the guide expects the vertex to reflect towards the previous
// one: NEE's unweighted estimate (direct) plus the learned integral. It
// completes the pending target, and gives guide-driven roulette the path's
// expected radiance.
template <class Ctx>
TESSERA_HOST_DEVICE TESSERA_INLINE void guide_vertex_estimate(Ctx& x, PathState& st, const SurfaceVertex& v, bool nee_vertex,
                                                      Float direct) {
  const PendingTarget& pending = x.guide.pending;
  const bool completes_target = x.learn && pending.cell >= 0 && !pending.at_delta;
  const bool sets_expectation =
      x.guide_roulette && !(st.path_expected > 0.f) && !v.delta_lobe && x.guide.learned(v.cell);
  const bool records_nee = x.learn && nee_vertex;
  if (!(completes_target || sets_expectation || records_nee)) return;
  guide_vertex_estimate_at(x, st, v, direct, completes_target, sets_expectation, records_nee);
}

}  // namespace tessera
