// The BSDF as the integrator's specialisation sees it: scenes of Lambertian
// surfaces alone (kSpecNonDiffuse clear) evaluate and sample the diffuse lobe
// inline instead of the general BSDF's switch; kSpecTextures applies bump
// and normal maps to the shading frame.
#pragma once

#include "bsdf.h"
#include "bump.h"
#include "effects.h"
#include "sampling.h"
#include "surface.h"

namespace tessera {

namespace detail {

// Lambertian fast path used when the scene has no other BSDF.
TESSERA_HOST_DEVICE inline Rgb diffuse_eval(const BsdfParams& b, const Vec3& wo, const Vec3& wi) {
  return same_hemisphere(wo, wi) ? b.reflectance * kInvPi : Rgb(0.f);
}

}  // namespace detail

// Directions are taken by value: the general BSDF's code is out of line, and
// a reference would hand it the address of the caller's vertex, which the
// compiler must then keep in memory instead of registers.
template <uint32_t Spec>
TESSERA_HOST_DEVICE inline Rgb eval_f(const BsdfParams& b, Vec3 wo, Vec3 wi) {
  if constexpr ((Spec & kSpecNonDiffuse) != 0) return bsdf_eval(b, wo, wi);
  else return detail::diffuse_eval(b, wo, wi);
}
// For light samples (next-event estimation): see bsdf_eval_light.
template <uint32_t Spec>
TESSERA_HOST_DEVICE inline Rgb eval_f_light(const BsdfParams& b, Vec3 wo, Vec3 wi) {
  if constexpr ((Spec & kSpecNonDiffuse) != 0) return bsdf_eval_light(b, wo, wi);
  else return detail::diffuse_eval(b, wo, wi);
}
template <uint32_t Spec>
TESSERA_HOST_DEVICE inline Float eval_pdf(const BsdfParams& b, Vec3 wo, Vec3 wi) {
  if constexpr ((Spec & kSpecNonDiffuse) != 0) return bsdf_pdf(b, wo, wi);
  else return same_hemisphere(wo, wi) ? abs_cos_theta(wi) * kInvPi : 0.f;
}
// The density MIS weighs the BSDF's strategy by (bsdf_mis_pdf), and whether
// the balance heuristic applies (the coated BSDFs under volpath).
template <uint32_t Spec>
TESSERA_HOST_DEVICE inline Float eval_mis_pdf(const BsdfParams& b, Vec3 wo, Vec3 wi, Float pdf) {
  if constexpr ((Spec & kSpecNonDiffuse) != 0) return bsdf_mis_estimated(b) ? bsdf_mis_pdf(b, wo, wi) : pdf;
  else return pdf;
}
template <uint32_t Spec>
TESSERA_HOST_DEVICE inline bool mis_balance(const SceneView& s, const BsdfParams& b) {
  if constexpr ((Spec & kSpecNonDiffuse) != 0) return s.layered_mis_balance && bsdf_mis_estimated(b);
  else return false;
}
template <uint32_t Spec>
TESSERA_HOST_DEVICE inline bool sample_f(const BsdfParams& b, Vec3 wo, Float uc, Vec2 u, BsdfSample* bs) {
  if constexpr ((Spec & kSpecNonDiffuse) != 0) {
    return bsdf_sample(b, wo, uc, u, bs);
  } else {
    (void)uc;
    Vec3 wi = sample_cosine_hemisphere(u);
    if (wo.z < 0.f) wi.z = -wi.z;
    if (wi.z == 0.f) return false;
    bs->wi = wi;
    bs->pdf = abs_cos_theta(wi) * kInvPi;
    bs->f = b.reflectance * kInvPi;
    bs->lobe = kLobeReflection | kLobeDiffuse;
    bs->eta = 1.f;
    return bs->pdf > 0.f;
  }
}

// The shading frame at a hit: the material's bump or normal map applied to
// h.ns first (kSpecTextures). Anisotropic BSDFs need pbrt's orientation (x
// along dp/du); any frame around the normal serves the isotropic ones.
template <uint32_t Spec>
TESSERA_HOST_DEVICE inline Frame shading_frame(const SceneView& s, const BsdfParams& bsdf, SurfaceHit& h) {
  if constexpr ((Spec & kSpecTextures) != 0) {
    if (bsdf.bump >= 0) h.ns = bumped_shading_normal(s, bsdf.bump, h);
    else if (bsdf.normal_map >= 0) h.ns = normal_mapped_shading_normal(s, bsdf.normal_map, h);
  }
  // Hair: x along the fibre (a curve's u).
  return (Spec & kSpecNonDiffuse) && (bsdf.alpha_x != bsdf.alpha_y || bsdf.type == BsdfType::Hair)
             ? Frame::from_tangent(h.ns, surface_dpdu(s, h))
             : Frame::from_z(h.ns);
}

template <uint32_t Spec>
TESSERA_HOST_DEVICE inline uint32_t lobes_of(const BsdfParams& b) {
  return (Spec & kSpecNonDiffuse) ? bsdf_lobes(b) : (kLobeReflection | kLobeDiffuse);
}

}  // namespace tessera
