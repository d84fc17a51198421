// Emission the path finds by scattering: an area light it hits, and the
// environment where it leaves the scene (the integrator's escape stage).
#pragma once

#include "integrator/integrator_context.h"
#include "kernels/light_choice.h"
#include "kernels/light_sampling.h"

namespace tessera {

// The density MIS weighs the last sampled direction by: taken from the
// vertex's coated BSDF only now that the direction found a light (MisMemory).
template <uint32_t Spec>
TESSERA_HOST_DEVICE TESSERA_INLINE Float last_direction_mis_pdf(MisMemory& m) {
  if constexpr ((Spec & kSpecNonDiffuse) != 0) {
    if (m.pending) {
      // Copies: the coated BSDF's code is out of line, and the path state's
      // address must not reach it (the state would then live in memory).
      const BsdfParams bsdf = m.bsdf;
      const Vec3 wo = m.wo, wi = m.wi;
      const Float mis_bsdf = bsdf_mis_pdf(bsdf, wo, wi);
      m.pdf = m.guide_p * m.guide_density + (1.f - m.guide_p) * mis_bsdf;
      m.pending = false;
    }
  }
  return m.pdf;
}

// Adds emitted radiance Le of light li found along the last direction: all
// of it where next-event estimation could not have sampled it (the camera
// ray, a specular bounce, no NEE), else weighted by MIS against NEE's
// density, light_pdf_of() (the light's density of the direction, without
// its selection probability; evaluated only here).
template <class Ctx, class LightPdf>
TESSERA_HOST_DEVICE TESSERA_INLINE void add_found_emission(Ctx& x, PathState& st, uint32_t li, const Rgb& Le,
                                                   const LightPdf& light_pdf_of) {
  if (st.depth == 0 || st.specular_bounce || !x.settings.nee) {
    st.L += st.beta * Le;
    return;
  }
  const Float light_pdf = x.guide.light_pmf(x.s, LightQuery{st.mis.p, st.mis.n}, st.mis.cell, li) * light_pdf_of();
  st.L += st.beta * Le * mis_weight(last_direction_mis_pdf<Ctx::kSpec>(st.mis), light_pdf, st.mis.balance);
  if constexpr (Ctx::kGuide) learning_note_emission(x.guide, luminance(Le), light_pdf);
}

// The path hit an area light's triangle: its emission towards the previous
// vertex (returned: the guide's targets need it), unless the light tracer
// delivers it (light-traced caustics).
template <class Ctx>
TESSERA_HOST_DEVICE TESSERA_INLINE Rgb add_area_emission(Ctx& x, PathState& st, const SurfaceHit& h, const Vec3& wo,
                                                 int32_t light) {
  const Light& l = x.s.lights[light];
  const Float cos_l = glm::dot(h.ng, wo);
  if (!(l.two_sided || cos_l > 0.f)) return Rgb(0.f);
  if (st.first_vertex_connectable && st.last_vertex_delta_only) {
    ++x.c.caustic_emission_skipped;
    return Rgb(0.f);
  }
  const Rgb Le = light_emission(x.s, st.wl, l, area_light_radiance(x.s, l, h.uv));
  add_found_emission(x, st, static_cast<uint32_t>(light), Le,
                     [&] { return area_light_pdf_from(x.s, l, st.mis.p, h.p, cos_l, st.mis.in_medium); });
  return Le;
}

// Escape stage: the ray left the scene. The environment's lights add their
// radiance along it, and a pending learning target ends here.
template <class Ctx>
TESSERA_HOST_DEVICE TESSERA_INLINE void escape(Ctx& x, PathState& st) {
  Rgb Le_total(0.f);
  if constexpr ((Ctx::kSpec & kSpecEnvironment) != 0) {
    for (uint32_t k = 0; k < x.s.num_infinite_lights; ++k) {
      const uint32_t li = static_cast<uint32_t>(x.s.infinite_lights[k]);
      // A portal's sky is seen through its rectangle from the last scattering point (where NEE
      // sampled it; the camera's position for camera rays): not from an interface the ray crossed since.
      const Vec3 from = st.depth == 0 ? st.ray.o : st.mis.p;
      const Light& l = x.s.lights[li];
      const Rgb Le = light_emission(x.s, st.wl, l, environment_radiance(x.s, l, from, st.ray.d));
      Le_total += Le;
      add_found_emission(x, st, li, Le, [&] { return environment_pdf(x.s, li, from, st.ray.d); });
    }
  }
  if constexpr (Ctx::kGuide) {
    const bool counted = st.specular_bounce || !x.settings.nee;  // else NEE delivers the environment
    learning_at_escape(x.guide, counted ? luminance(Le_total) : 0.f, st.segment_tr, x.c.guide_updates);
  }
}

}  // namespace tessera
