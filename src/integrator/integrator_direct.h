// Direct light (pbrt-v4's SampleLd): next-event estimation with multiple
// importance sampling at a scattering point, on a surface (SurfaceScatter:
// the BSDF, and the guide mixture where the vertex is guided) or in a
// medium (PhaseScatter: Henyey-Greenstein). One shadow ray to one light.
#pragma once

#include "integrator/integrator_context.h"
#include "kernels/light_choice.h"
#include "kernels/light_sampling.h"
#include "kernels/volume_transport.h"

namespace tessera {

// A surface vertex as next-event estimation sees it.
template <uint32_t Spec>
struct SurfaceScatter {
  const SceneView& s;
  const SurfaceHit& h;
  const BsdfParams& bsdf;
  const Frame& frame;
  Vec3 wo_l;       // towards the previous vertex, shading frame
  int32_t medium;  // the medium the path is in
  static constexpr bool kInMedium = false;
  TESSERA_HOST_DEVICE Vec3 point() const { return h.p; }
  TESSERA_HOST_DEVICE LightQuery light_query() const { return {h.p, h.ns}; }
  TESSERA_HOST_DEVICE Vec3 local(const Vec3& wi) const { return frame.to_local(wi); }
  // The BSDF times the cosine for a light sample's direction (and a scalar
  // factor of it: see PhaseScatter).
  TESSERA_HOST_DEVICE Rgb f(const Vec3& wi_l) const { return eval_f_light<Spec>(bsdf, wo_l, wi_l) * abs_cos_theta(wi_l); }
  TESSERA_HOST_DEVICE Float scale(const Vec3&) const { return 1.f; }
  TESSERA_HOST_DEVICE Float pdf(const Vec3& wi_l) const { return eval_pdf<Spec>(bsdf, wo_l, wi_l); }
  TESSERA_HOST_DEVICE Float mis_pdf(const Vec3& wi_l, Float pdf) const { return eval_mis_pdf<Spec>(bsdf, wo_l, wi_l, pdf); }
  TESSERA_HOST_DEVICE bool balance() const { return mis_balance<Spec>(s, bsdf); }
  TESSERA_HOST_DEVICE Vec3 origin(const Vec3& wi) const { return offset_ray_origin(h, wi); }
  TESSERA_HOST_DEVICE int32_t shadow_medium(const Vec3& wi) const {
    if constexpr ((Spec & kSpecMedia) != 0) return medium_after(s, h.triangle, h.ng, wi, medium);
    else return -1;
  }
};

// A scattering point in a medium: the phase function stands for f and its
// pdf. It is a scalar: it scales the light's weight (w / pdf) instead of
// multiplying a colour, and the unweighted estimate is taken per light
// density as a whole (the volumetric integrator's order of operations).
struct PhaseScatter {
  Vec3 p;
  Vec3 wo;
  Float g;         // Henyey-Greenstein asymmetry
  int32_t medium;
  static constexpr bool kInMedium = true;
  TESSERA_HOST_DEVICE Vec3 point() const { return p; }
  TESSERA_HOST_DEVICE LightQuery light_query() const { return {p, Vec3(0.f)}; }
  TESSERA_HOST_DEVICE Float local(const Vec3& wi) const { return henyey_greenstein(glm::dot(wo, wi), g); }
  TESSERA_HOST_DEVICE Rgb f(Float) const { return Rgb(1.f); }
  TESSERA_HOST_DEVICE Float scale(Float phase) const { return phase; }
  TESSERA_HOST_DEVICE Float pdf(Float phase) const { return phase; }
  TESSERA_HOST_DEVICE Float mis_pdf(Float, Float pdf) const { return pdf; }
  TESSERA_HOST_DEVICE bool balance() const { return false; }
  TESSERA_HOST_DEVICE Vec3 origin(const Vec3&) const { return p; }
  TESSERA_HOST_DEVICE int32_t shadow_medium(const Vec3&) const { return medium; }
};

// What direct light tells the guide (learning paths): its unweighted
// estimate of the light reflected at the vertex, and the next-event
// sample's share of the mixture statistics (guided vertices).
struct DirectLight {
  Float estimate = 0.f;
  GuideMixSample mix;
};

// Next-event estimation at the scattering point `at` with the guide's
// vertex `cell` (-1: none) sampling with probability guide_p (0: the BSDF
// alone): adds the MIS-weighted light to st.L. Where the guide has learned
// that shadow rays bring little, the vertex traces one with probability
// p_nee (the same number decides, rescaled).
template <class Ctx, class Scatter>
TESSERA_HOST_DEVICE TESSERA_INLINE DirectLight sample_direct(Ctx& x, PathState& st, const Scatter& at, int32_t cell,
                                                     Float guide_p, Float u_select, Vec2 u_light) {
  DirectLight d;
  bool traced = true;
  const Float p_nee = x.guide.nee_probability(cell);
  if (p_nee < 1.f) {
    traced = u_select < p_nee;
    u_select = glm::min(u_select / p_nee, 0x1.fffffep-1f);
  }
  Float pmf = 0.f;
  uint32_t li = 0;
  if (traced) li = x.guide.pick_light(x.s, at.light_query(), cell, u_select, &pmf);
  else ++x.c.nee_skipped;
  LightSample ls;
  Float learned = 0.f;  // unoccluded contribution of the selected light, for the guide
  if (pmf > 0.f && sample_light(x.s, li, at.point(), u_light, &ls, Scatter::kInMedium)) {
    ls.L = light_emission(x.s, st.wl, x.s.lights[li], ls.L);
    const auto wi_l = at.local(ls.wi);
    const Rgb f = at.f(wi_l);
    if (!is_black(f)) {
      const Vec3 o = at.origin(ls.wi);
      Float tmax = kInfinity;
      if (!ls.infinite) tmax = glm::length(ls.p_light - o) * 0.9999f;
      const Float light_pdf = pmf * ls.pdf;
      // The guide's density of the light direction, for the MIS weight: its
      // memory is fetched while the shadow ray is traced.
      typename Ctx::Guide::DirLookup light_dir{};
      const bool guided_light_dir = guide_p > 0.f && !ls.delta;
      if (guided_light_dir) light_dir = x.guide.lookup(cell, ls.wi);
      const Rgb tr = light_pdf > 0.f ? light_visibility<Ctx::kMedia>(x.s, x.tracer, o, ls.wi, tmax, at.shadow_medium(ls.wi),
                                                                     st.ray.time, x.c, st.wl)
                                     : Rgb(0.f);
      if (!is_black(tr)) {
        Float w = 1.f;
        if (!ls.delta) {
          const Float scatter_pdf = at.pdf(wi_l);
          Float mis_pdf = at.mis_pdf(wi_l, scatter_pdf);
          if (guided_light_dir) {
            const Float guide_pdf_l = x.guide.lookup_pdf(light_dir);
            if (x.learn) {
              d.mix.nee_value = luminance(f * tr * ls.L);
              d.mix.nee_light_pdf = light_pdf;
              d.mix.nee_guide_pdf = guide_pdf_l;
              d.mix.nee_bsdf_pdf = scatter_pdf;
            }
            mis_pdf = guide_p * guide_pdf_l + (1.f - guide_p) * mis_pdf;
          }
          w = mis_weight(light_pdf, mis_pdf, at.balance());
        }
        st.L += st.beta * f * tr * ls.L * (at.scale(wi_l) * w / light_pdf);
        const Float unoccluded = luminance(f * tr * ls.L);
        learned = unoccluded / ls.pdf;
        if constexpr (Scatter::kInMedium) d.estimate = unoccluded * at.scale(wi_l) / light_pdf;
      }
    }
  }
  if (x.learn && pmf > 0.f && cell >= 0) x.guide.record_light(cell, li, learned);
  if constexpr (!Scatter::kInMedium) d.estimate = pmf > 0.f ? learned / pmf : 0.f;
  return d;
}

}  // namespace tessera
