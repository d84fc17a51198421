// Unidirectional path tracing with next-event estimation and MIS (power
// heuristic), Russian roulette, pbrt-v4's depth counting, as a loop over
// stages that each do one thing (the split a wavefront renderer would run
// as separate kernels, PathState between them):
//   trace the segment -> medium interaction (integrator_medium.h)
//   -> escape (integrator_emission.h) or surface interaction
//   (integrator_surface.h) -> direct light (integrator_direct.h) -> the
//   vertex's estimate for the guide -> BSDF or guided scattering -> Russian
//   roulette (integrator_scatter.h).
// Templated on the scene's specialisation bits (effects.h) and on the
// ray-query backend, which provides (time: Ray::time, for moving shapes):
//   bool intersect(const Vec3& o, const Vec3& d, Float tmax, TraceHit* hit, Float time) const;
//   bool occluded(const Vec3& o, const Vec3& d, Float tmax, Float time) const;   // d unit length
//
// With kSpecMedia the path also scatters in participating media (pbrt-v4's
// volpath): the ray starts in the camera's medium, changes medium where it
// crosses a surface that is a medium transition, and each segment through a
// medium samples a collision. Shadow rays accumulate transmittance through
// "interface" surfaces (volume_transport.h).
//
// With kSpecGuiding, directions at vertices without a delta lobe are drawn
// from a mixture of the BSDF and the learned guide (path_guide.h), and the
// path's learning targets go to the guide through its hooks
// (path_learning.h). (Weighing MIS by the BSDF pdf alone, which saves NEE a
// guide lookup, measured 5 % worse on shelter at equal samples and no faster.)
#pragma once

#include "integrator/integrator_medium.h"

namespace tessera {

// A learning path's vertex took direction r (BSDF weight `weight`): its
// target becomes the pending one, with the vertex's mixture statistics
// (direct: next-event estimation's share). Out of line on the GPU, as
// learning is (path_learning.h).
template <class Ctx>
TESSERA_HOST_DEVICE TESSERA_COLD_STAGE void learn_at_scatter(Ctx& x, const PathState& st, const SurfaceVertex& v,
                                                             const ScatterSample& r, Float guide_p,
                                                             const GuideMixSample& direct, const Rgb& weight) {
  // Only vertices that sample with the cell's own weight (not faded by a
  // glossy lobe) inform it.
  GuideMixSample mix = direct;
  if (guide_p > 0.f && x.guide.learns_mix(v.cell, guide_p)) {
    mix.fcos = luminance(r.bs.f) * abs_cos_theta(r.bs.wi);
    mix.bsdf_pdf = r.bsdf_pdf;
    mix.guide_pdf = r.guide_density;
    mix.mix_pdf = r.pdf;
  }
  learning_at_scatter(x.guide, v.cell, r.bin, luminance(weight), mix, st.segment_tr, x.c.guide_updates);
}

// One surface vertex after its interaction: direct light, the guide's
// estimate, the direction, the path's state after it. False: the path ends.
template <class Ctx>
TESSERA_HOST_DEVICE TESSERA_INLINE bool scatter_at_surface(Ctx& x, PathState& st, const SurfaceVertex& v) {
  const Float guide_p = vertex_guide_probability(x, st, v);
  // The direction's random numbers are drawn before next-event estimation so
  // that the guide's alias entry can be fetched while the shadow ray is traced.
  const Float uc = x.rng.uniform();
  const Vec2 u = x.rng.uniform2();
  if (guide_p > 0.f) x.guide.prefetch_sample(v.cell, uc);

  DirectLight direct;
  const bool nee_vertex = x.settings.nee && lobes_have_non_specular(v.lobes) && x.s.num_lights > 0;
  if (nee_vertex) {
    const Float u_select = x.rng.uniform();
    const Vec2 u_light = x.rng.uniform2();
    const SurfaceScatter<Ctx::kSpec> at{x.s, v.h, v.bsdf, v.frame, v.wo_l, st.medium};
    direct = sample_direct(x, st, at, v.cell, guide_p, u_select, u_light);
  }
  if constexpr (Ctx::kGuide) guide_vertex_estimate(x, st, v, nee_vertex, direct.estimate);

  ScatterSample r;
  if (!sample_scatter(x, st, v, guide_p, uc, u, &r)) return false;
  const Rgb weight = r.bs.f * (abs_cos_theta(r.bs.wi) / r.pdf);
  if (Ctx::kGuide && x.learn) learn_at_scatter(x, st, v, r, guide_p, direct.mix, weight);
  move_past_surface(x, st, v, r, weight, guide_p);
  return survives_roulette(x, st, v.cell, r.bin);
}

// Radiance arriving along the ray; consumes random numbers from rng in a fixed order.
template <uint32_t Spec, class Tracer>
TESSERA_HOST_DEVICE Rgb trace_path(const SceneView& s, const Tracer& tracer, Ray ray, PixelSampler& rng,
                                   const PathSettings& settings, PathCounters& c, Wavelengths* wl = nullptr) {
  auto guide = make_path_guide<Spec>(settings);
  using Ctx = PathContext<Spec, Tracer, decltype(guide)>;
  Ctx x{s, tracer, settings, rng, guide, c, Ctx::kGuide && settings.learn, Ctx::kGuide && settings.guided_roulette};
  PathState st;
  st.ray = ray;
  st.wl = wl;
  if constexpr ((Spec & kSpecMedia) != 0) st.medium = s.camera_medium;
  for (;;) {
    TraceHit hit{};
    ++c.rays;
    st.segment_tr = 1.f;
    const bool found = tracer.intersect(st.ray.o, st.ray.d, kInfinity, &hit, st.ray.time);
    if constexpr ((Spec & kSpecMedia) != 0) {
      if (st.medium >= 0) {
        const MediumStep m = medium_interaction(x, st, found ? hit.t : kInfinity);
        if (m == MediumStep::kEnd) break;
        if (m == MediumStep::kScattered) continue;
      }
    }
    if (!found) {
      escape(x, st);
      break;
    }
    SurfaceHit h;
    BsdfParams bsdf;
    SurfaceVertex v(h, bsdf);
    const SurfaceStep step = surface_interaction(x, st, hit, &v);
    if (step == SurfaceStep::kPass) continue;
    if (step == SurfaceStep::kEnd || !scatter_at_surface(x, st, v)) break;
  }
  return st.L;
}

}  // namespace tessera
