// Inline definitions for bsdf.h. pbrt-v4 semantics (bxdfs.h / bxdfs.cpp),
// TransportMode::Radiance. Every function returns finite values; samples that
// pbrt would reject (black f, zero pdf, wi.z == 0) make bsdf_sample return false.
#pragma once

#include "fresnel.h"
#include "hair.h"
#include "medium.h"
#include "microfacet.h"
#include "rng.h"
#include "sampling.h"

namespace tessera {

namespace bsdf_detail {

TESSERA_HOST_DEVICE inline bool finite_f(Float x) { return fabsf(x) <= 3.4e38f; }
TESSERA_HOST_DEVICE inline Rgb finite_or_zero(const Rgb& c) { return is_finite(c) ? c : Rgb(0.f); }
TESSERA_HOST_DEVICE inline Float finite_or_zero(Float x) { return finite_f(x) ? x : 0.f; }
TESSERA_HOST_DEVICE inline Vec3 face_forward_z(const Vec3& v) { return v.z < 0.f ? -v : v; }
TESSERA_HOST_DEVICE inline Float len2(const Vec3& v) { return glm::dot(v, v); }
TESSERA_HOST_DEVICE inline TrowbridgeReitz distrib(const BsdfParams& b) { return TrowbridgeReitz(b.alpha_x, b.alpha_y); }
TESSERA_HOST_DEVICE inline Float dielectric_eta(const BsdfParams& b) { return b.ior > 0.f ? b.ior : 1.f; }

// ---------------------------------------------------------------- Diffuse ---
TESSERA_HOST_DEVICE inline Rgb diffuse_f(const BsdfParams& b, const Vec3& wo, const Vec3& wi) {
  if (!same_hemisphere(wo, wi)) return Rgb(0.f);
  return b.reflectance * kInvPi;
}
TESSERA_HOST_DEVICE inline Float diffuse_pdf(const BsdfParams& b, const Vec3& wo, const Vec3& wi) {
  if (!same_hemisphere(wo, wi)) return 0.f;
  return cosine_hemisphere_pdf(abs_cos_theta(wi));
}
TESSERA_HOST_DEVICE inline bool diffuse_sample(const BsdfParams& b, const Vec3& wo, Float, Vec2 u, BsdfSample* s) {
  Vec3 wi = sample_cosine_hemisphere(u);
  if (wo.z < 0.f) wi.z = -wi.z;
  s->wi = wi;
  s->f = b.reflectance * kInvPi;
  s->pdf = cosine_hemisphere_pdf(abs_cos_theta(wi));
  s->lobe = kLobeReflection | kLobeDiffuse;
  s->eta = 1.f;
  return true;
}

// ---------------------------------------------------- DiffuseTransmission ---
// pbrt-v4 DiffuseTransmissionBxDF: R/pi on wo's side, T/pi through; the side
// is chosen in proportion to the largest channel of R and of T.
TESSERA_HOST_DEVICE inline Rgb diffuse_transmission_f(const BsdfParams& b, const Vec3& wo, const Vec3& wi) {
  return (same_hemisphere(wo, wi) ? b.reflectance : b.transmittance) * kInvPi;
}
TESSERA_HOST_DEVICE inline Float diffuse_transmission_pr(const BsdfParams& b, bool reflect) {
  const Float pr = max_component(b.reflectance), pt = max_component(b.transmittance);
  if (!(pr + pt > 0.f)) return 0.f;
  return (reflect ? pr : pt) / (pr + pt);
}
TESSERA_HOST_DEVICE inline Float diffuse_transmission_pdf(const BsdfParams& b, const Vec3& wo, const Vec3& wi) {
  return diffuse_transmission_pr(b, same_hemisphere(wo, wi)) * cosine_hemisphere_pdf(abs_cos_theta(wi));
}
TESSERA_HOST_DEVICE inline bool diffuse_transmission_sample(const BsdfParams& b, const Vec3& wo, Float uc, Vec2 u,
                                                            BsdfSample* s) {
  const Float p_reflect = diffuse_transmission_pr(b, true);
  if (!(p_reflect > 0.f) && !(diffuse_transmission_pr(b, false) > 0.f)) return false;
  const bool reflect = uc < p_reflect;
  Vec3 wi = sample_cosine_hemisphere(u);
  if ((wo.z < 0.f) == reflect) wi.z = -wi.z;  // reflection stays on wo's side
  s->wi = wi;
  s->f = diffuse_transmission_f(b, wo, wi);
  s->pdf = diffuse_transmission_pdf(b, wo, wi);
  s->lobe = (reflect ? kLobeReflection : kLobeTransmission) | kLobeDiffuse;
  s->eta = 1.f;
  return true;
}

// -------------------------------------------------------------- Conductor ---
TESSERA_HOST_DEVICE inline Rgb conductor_f(const BsdfParams& b, const Vec3& wo, const Vec3& wi) {
  if (!same_hemisphere(wo, wi)) return Rgb(0.f);
  TrowbridgeReitz d = distrib(b);
  if (d.effectively_smooth()) return Rgb(0.f);
  Float cos_o = abs_cos_theta(wo), cos_i = abs_cos_theta(wi);
  if (cos_i == 0.f || cos_o == 0.f) return Rgb(0.f);
  Vec3 wm = wi + wo;
  if (len2(wm) == 0.f) return Rgb(0.f);
  wm = glm::normalize(wm);
  Rgb F = fr_complex(fabsf(glm::dot(wo, wm)), b.eta, b.k);
  return finite_or_zero(d.D(wm) * F * d.G(wo, wi) / (4.f * cos_i * cos_o));
}
TESSERA_HOST_DEVICE inline Float conductor_pdf(const BsdfParams& b, const Vec3& wo, const Vec3& wi) {
  if (!same_hemisphere(wo, wi)) return 0.f;
  TrowbridgeReitz d = distrib(b);
  if (d.effectively_smooth()) return 0.f;
  Vec3 wm = wo + wi;
  if (len2(wm) == 0.f) return 0.f;
  wm = face_forward_z(glm::normalize(wm));
  Float dot_om = fabsf(glm::dot(wo, wm));
  if (dot_om == 0.f) return 0.f;
  return finite_or_zero(d.pdf(wo, wm) / (4.f * dot_om));
}
TESSERA_HOST_DEVICE inline bool conductor_sample(const BsdfParams& b, const Vec3& wo, Float, Vec2 u, BsdfSample* s) {
  TrowbridgeReitz d = distrib(b);
  if (d.effectively_smooth()) {
    Vec3 wi(-wo.x, -wo.y, wo.z);
    Float c = abs_cos_theta(wi);
    s->wi = wi;
    s->f = fr_complex(c, b.eta, b.k) / c;
    s->pdf = 1.f;
    s->lobe = kLobeReflection | kLobeSpecular;
    s->eta = 1.f;
    return true;
  }
  Vec3 wm = d.sample_wm(wo, u);
  Vec3 wi = reflect(wo, wm);
  if (!same_hemisphere(wo, wi)) return false;
  Float dot_om = fabsf(glm::dot(wo, wm));
  Float cos_o = abs_cos_theta(wo), cos_i = abs_cos_theta(wi);
  if (dot_om == 0.f || cos_i == 0.f || cos_o == 0.f) return false;
  s->wi = wi;
  s->pdf = d.pdf(wo, wm) / (4.f * dot_om);
  Rgb F = fr_complex(dot_om, b.eta, b.k);
  s->f = d.D(wm) * F * d.G(wo, wi) / (4.f * cos_i * cos_o);
  s->lobe = kLobeReflection | kLobeGlossy;
  s->eta = 1.f;
  return true;
}

// ------------------------------------------------------------- Dielectric ---
// eta = ior = n_inside / n_outside; pbrt-v4 DielectricBxDF. Directions with
// wo.z < 0 see 1/ior through fr_dielectric / refract's own flipping.
TESSERA_HOST_DEVICE inline bool dielectric_is_specular(const BsdfParams& b) {
  return dielectric_eta(b) == 1.f || distrib(b).effectively_smooth();
}

// Generalised half vector for (wo, wi); false when the configuration is
// impossible (pbrt's degenerate / back-facing microfacet checks).
TESSERA_HOST_DEVICE inline bool dielectric_half_vector(Float eta, const Vec3& wo, const Vec3& wi, Vec3* wm_out,
                                                       Float* etap_out, bool* reflect_out) {
  Float cos_o = cos_theta(wo), cos_i = cos_theta(wi);
  bool refl = cos_i * cos_o > 0.f;
  Float etap = 1.f;
  if (!refl) etap = cos_o > 0.f ? eta : (1.f / eta);
  Vec3 wm = wi * etap + wo;
  if (cos_i == 0.f || cos_o == 0.f || len2(wm) == 0.f) return false;
  wm = face_forward_z(glm::normalize(wm));
  if (glm::dot(wm, wi) * cos_i < 0.f || glm::dot(wm, wo) * cos_o < 0.f) return false;
  *wm_out = wm;
  *etap_out = etap;
  *reflect_out = refl;
  return true;
}

TESSERA_HOST_DEVICE inline Rgb dielectric_f(const BsdfParams& b, const Vec3& wo, const Vec3& wi) {
  if (dielectric_is_specular(b)) return Rgb(0.f);
  Float eta = dielectric_eta(b);
  TrowbridgeReitz d = distrib(b);
  Vec3 wm;
  Float etap;
  bool refl;
  if (!dielectric_half_vector(eta, wo, wi, &wm, &etap, &refl)) return Rgb(0.f);
  Float F = fr_dielectric(glm::dot(wo, wm), eta);
  Float cos_o = cos_theta(wo), cos_i = cos_theta(wi);
  if (refl) return Rgb(finite_or_zero(d.D(wm) * d.G(wo, wi) * F / fabsf(4.f * cos_i * cos_o)));
  Float dim = glm::dot(wi, wm), dom = glm::dot(wo, wm);
  Float denom = sqr(dim + dom / etap) * cos_i * cos_o;
  if (denom == 0.f) return Rgb(0.f);
  Float ft = d.D(wm) * (1.f - F) * d.G(wo, wi) * fabsf(dim * dom / denom);
  ft /= sqr(etap);  // radiance transport
  return Rgb(finite_or_zero(ft));
}

TESSERA_HOST_DEVICE inline Float dielectric_pdf(const BsdfParams& b, const Vec3& wo, const Vec3& wi) {
  if (dielectric_is_specular(b)) return 0.f;
  Float eta = dielectric_eta(b);
  TrowbridgeReitz d = distrib(b);
  Vec3 wm;
  Float etap;
  bool refl;
  if (!dielectric_half_vector(eta, wo, wi, &wm, &etap, &refl)) return 0.f;
  Float R = fr_dielectric(glm::dot(wo, wm), eta), T = 1.f - R;
  if (!(R + T > 0.f)) return 0.f;
  Float pdf;
  if (refl) {
    Float dom = fabsf(glm::dot(wo, wm));
    if (dom == 0.f) return 0.f;
    pdf = d.pdf(wo, wm) / (4.f * dom) * R / (R + T);
  } else {
    Float denom = sqr(glm::dot(wi, wm) + glm::dot(wo, wm) / etap);
    if (denom == 0.f) return 0.f;
    Float dwm_dwi = fabsf(glm::dot(wi, wm)) / denom;
    pdf = d.pdf(wo, wm) * dwm_dwi * T / (R + T);
  }
  return finite_or_zero(pdf);
}

TESSERA_HOST_DEVICE inline bool dielectric_sample(const BsdfParams& b, const Vec3& wo, Float uc, Vec2 u,
                                                  BsdfSample* s) {
  Float eta = dielectric_eta(b);
  TrowbridgeReitz d = distrib(b);
  if (dielectric_is_specular(b)) {
    Float R = fr_dielectric(cos_theta(wo), eta), T = 1.f - R;
    if (!(R + T > 0.f)) return false;
    if (uc < R / (R + T)) {
      Vec3 wi(-wo.x, -wo.y, wo.z);
      s->wi = wi;
      s->f = Rgb(R / abs_cos_theta(wi));
      s->pdf = R / (R + T);
      s->lobe = kLobeReflection | kLobeSpecular;
      s->eta = 1.f;
      return true;
    }
    Vec3 wi;
    Float etap = 1.f;
    if (!refract(wo, Vec3(0.f, 0.f, 1.f), eta, &etap, &wi)) return false;
    if (wi.z == 0.f) return false;
    s->wi = wi;
    s->f = Rgb(T / abs_cos_theta(wi) / sqr(etap));
    s->pdf = T / (R + T);
    s->lobe = kLobeTransmission | kLobeSpecular;
    s->eta = etap;
    return true;
  }
  Vec3 wm = d.sample_wm(wo, u);
  Float dom = glm::dot(wo, wm);
  Float R = fr_dielectric(dom, eta), T = 1.f - R;
  if (!(R + T > 0.f)) return false;
  if (uc < R / (R + T)) {
    Vec3 wi = reflect(wo, wm);
    if (!same_hemisphere(wo, wi)) return false;
    Float adom = fabsf(dom);
    Float cc = cos_theta(wi) * cos_theta(wo);
    if (adom == 0.f || cc == 0.f) return false;
    s->wi = wi;
    s->pdf = d.pdf(wo, wm) / (4.f * adom) * R / (R + T);
    s->f = Rgb(d.D(wm) * d.G(wo, wi) * R / (4.f * cc));
    s->lobe = kLobeReflection | kLobeGlossy;
    s->eta = 1.f;
    return true;
  }
  Vec3 wi;
  Float etap = 1.f;
  if (!refract(wo, wm, eta, &etap, &wi)) return false;
  if (same_hemisphere(wo, wi) || wi.z == 0.f) return false;
  Float dim = glm::dot(wi, wm);
  Float denom = sqr(dim + dom / etap);
  Float cc = cos_theta(wi) * cos_theta(wo);
  if (denom == 0.f || cc == 0.f) return false;
  Float dwm_dwi = fabsf(dim) / denom;
  s->wi = wi;
  s->pdf = d.pdf(wo, wm) * dwm_dwi * T / (R + T);
  s->f = Rgb(T * d.D(wm) * d.G(wo, wi) * fabsf(dim * dom / (cc * denom)) / sqr(etap));
  s->lobe = kLobeTransmission | kLobeGlossy;
  s->eta = etap;
  return true;
}

// --------------------------------------------------------- ThinDielectric ---
// pbrt-v4's ThinDielectricBxDF: a sheet of glass (a window) whose two
// parallel faces reflect R and transmit T at the incidence angle; the light
// bouncing inside leaves either way, so it reflects R + T^2 R / (1 - R^2) and
// the rest goes straight through, undeflected (no eta^2 scaling: it leaves
// into the medium it came from). Both lobes are deltas.
TESSERA_HOST_DEVICE inline Float thin_dielectric_reflectance(const BsdfParams& b, Float cos_o) {
  Float R = fr_dielectric(fabsf(cos_o), dielectric_eta(b));
  const Float T = 1.f - R;
  if (R < 1.f) R += T * T * R / (1.f - R * R);
  return R;
}

TESSERA_HOST_DEVICE inline bool thin_dielectric_sample(const BsdfParams& b, const Vec3& wo, Float uc, BsdfSample* s) {
  const Float R = thin_dielectric_reflectance(b, wo.z), T = 1.f - R;
  const Float c = abs_cos_theta(wo);
  if (!(c > 0.f)) return false;
  if (uc < R / (R + T)) {
    s->wi = Vec3(-wo.x, -wo.y, wo.z);
    s->f = Rgb(R / c);
    s->pdf = R / (R + T);
    s->lobe = kLobeReflection | kLobeSpecular;
  } else {
    s->wi = -wo;
    s->f = Rgb(T / c);
    s->pdf = T / (R + T);
    s->lobe = kLobeTransmission | kLobeSpecular;
  }
  s->eta = 1.f;
  return s->pdf > 0.f;
}

// ---------------------------------------------------------- CoatedDiffuse ---
// pbrt-v4's "coateddiffuse": the value f(wo, wi) is pbrt-v4's own layered
// estimate (layered.h: a random walk between the dielectric coat and the
// Lambertian base, a pure function of the two directions). Directions are
// *sampled* from a closed-form stand-in, the
// classic "plastic" model (Weidlich & Wilkie; Kelemen & Szirmay-Kalos):
//
//   q(wo, wi) = p_spec * coat lobe + (1 - p_spec) * cos(wi) / pi
//
// whose density is known exactly, so bsdf_pdf() returns the true density of
// bsdf_sample() and MIS and guided mixtures stay exact; the sample's f is the
// layered estimate, so f/q has the expectation of pbrt-v4's value. The coat lobe is the
// dielectric's GGX reflection (alpha_x, alpha_y) or, for a smooth coat, the
// mirror delta with its exact weight F(cos_o) (pbrt's layered f() excludes
// that delta too). p_spec = clamp(F(cos_o) / (F(cos_o) + (1 - F(cos_o))
// lum(R)), 0.05, 0.95). Two-sided; reflection only.
TESSERA_HOST_DEVICE inline Float coated_p_spec(const BsdfParams& b, Float Fo) {
  Float denom = Fo + (1.f - Fo) * luminance(glm::clamp(b.reflectance, Rgb(0.f), Rgb(1.f)));
  Float p = denom > 0.f ? Fo / denom : 0.5f;
  return glm::clamp(p, 0.05f, 0.95f);
}

#include "layered.h"

// The sampling density q, wo and wi both with z > 0.
TESSERA_HOST_DEVICE inline Float coated_pdf_upper(const BsdfParams& b, const Vec3& wo, const Vec3& wi) {
  if (!(wo.z > 0.f) || !(wi.z > 0.f)) return 0.f;
  Float Fo = fr_dielectric(wo.z, dielectric_eta(b));
  Float ps = coated_p_spec(b, Fo);
  Float pdf = (1.f - ps) * cosine_hemisphere_pdf(wi.z);
  TrowbridgeReitz d = distrib(b);
  if (!d.effectively_smooth()) {
    Vec3 wm = wo + wi;
    if (len2(wm) > 0.f) {
      wm = glm::normalize(wm);
      Float dom = glm::dot(wo, wm);
      if (dom > 0.f) pdf += ps * d.pdf(wo, wm) / (4.f * dom);
    }
  }
  return finite_or_zero(pdf);
}

TESSERA_HOST_DEVICE inline Vec3 flip_to_upper(const Vec3& v, bool flip) { return flip ? Vec3(v.x, v.y, -v.z) : v; }

TESSERA_HOST_DEVICE inline Rgb coated_f(const BsdfParams& b, const Vec3& wo, const Vec3& wi,
                                        layered::LayerWeights weights = layered::LayerWeights::Consistent) {
  return coated_diffuse_layered_f(b, wo, wi, weights);
}
TESSERA_HOST_DEVICE inline Float coated_pdf(const BsdfParams& b, const Vec3& wo, const Vec3& wi) {
  if (!same_hemisphere(wo, wi)) return 0.f;
  bool flip = wo.z < 0.f;
  return coated_pdf_upper(b, flip_to_upper(wo, flip), flip_to_upper(wi, flip));
}

TESSERA_HOST_DEVICE inline bool coated_sample(const BsdfParams& b, const Vec3& wo_in, Float uc, Vec2 u,
                                              BsdfSample* s) {
  bool flip = wo_in.z < 0.f;
  Vec3 wo = flip_to_upper(wo_in, flip);
  if (!(wo.z > 0.f)) return false;
  Float eta = dielectric_eta(b);
  Float Fo = fr_dielectric(wo.z, eta);
  Float ps = coated_p_spec(b, Fo);
  TrowbridgeReitz d = distrib(b);
  s->eta = 1.f;
  if (uc < ps) {
    if (d.effectively_smooth()) {
      Vec3 wi(-wo.x, -wo.y, wo.z);
      s->wi = flip_to_upper(wi, flip);
      s->f = Rgb(Fo / wo.z);
      s->pdf = ps;
      s->lobe = kLobeReflection | kLobeSpecular;
      return true;
    }
    Vec3 wm = d.sample_wm(wo, u);
    Vec3 wi = reflect(wo, wm);
    if (!(wi.z > 0.f)) return false;
    s->wi = flip_to_upper(wi, flip);
    s->f = coated_diffuse_layered_f(b, wo_in, s->wi);  // as bsdf_eval sees it: the same estimate
    s->pdf = coated_pdf_upper(b, wo, wi);
    s->lobe = kLobeReflection | kLobeGlossy;
    return true;
  }
  Vec3 wi = sample_cosine_hemisphere(u);
  if (!(wi.z > 0.f)) return false;
  s->wi = flip_to_upper(wi, flip);
  s->f = coated_diffuse_layered_f(b, wo_in, s->wi);
  s->pdf = coated_pdf_upper(b, wo, wi);
  s->lobe = kLobeReflection | kLobeDiffuse;
  return true;
}

#include "coated_conductor.h"

TESSERA_HOST_DEVICE inline HairFiber hair_fiber(const BsdfParams& b) {
  HairFiber h;
  h.sigma_a = b.hair_sigma_a;
  h.eta = b.ior;
  h.beta_m = b.hair_beta_m;
  h.beta_n = b.hair_beta_n;
  h.alpha = b.hair_alpha;
  return h;
}

// A hair BSDF's sample: glossy, reflection or transmission by the side of
// the round normal wi leaves on; nothing refracts into a medium (eta 1).
TESSERA_HOST_DEVICE inline bool hair_sample(const BsdfParams& b, const Vec3& wo, Float uc, Vec2 u, BsdfSample* s) {
  if (!tessera::hair_sample(hair_fiber(b), wo, uc, u, &s->wi, &s->f, &s->pdf)) return false;
  s->lobe = kLobeGlossy | (s->wi.z * wo.z > 0.f ? kLobeReflection : kLobeTransmission);
  s->eta = 1.f;
  return true;
}

// The side a walk leaves from is decided by the geometric normal
// (resolve_bsdf); the lobe is the shading normal's outer hemisphere,
// whatever side wo is on there.
TESSERA_HOST_DEVICE inline Rgb subsurface_exit_f(const BsdfParams& b, const Vec3& wo, const Vec3& wi) {
  if (!(wi.z > 0.f) || !(b.exit_norm > 0.f)) return Rgb(0.f);
  return Rgb((1.f - fr_dielectric(wi.z, b.ior)) * sqr(b.ior) / (b.exit_norm * kPi));
}

TESSERA_HOST_DEVICE inline Float subsurface_exit_pdf(const Vec3& wi) { return wi.z > 0.f ? wi.z * kInvPi : 0.f; }

TESSERA_HOST_DEVICE inline bool subsurface_exit_sample(const BsdfParams& b, const Vec3& wo, Vec2 u, BsdfSample* s) {
  s->wi = sample_cosine_hemisphere(u);
  s->pdf = subsurface_exit_pdf(s->wi);
  s->f = subsurface_exit_f(b, wo, s->wi);
  s->lobe = kLobeTransmission | kLobeDiffuse;
  s->eta = 1.f / b.ior;  // leaving the medium: undoes the entry's eta^2 for Russian roulette
  return true;
}

}  // namespace bsdf_detail

TESSERA_HOST_DEVICE TESSERA_DEVICE_NOINLINE inline Rgb bsdf_eval(const BsdfParams& b, const Vec3& wo, const Vec3& wi) {
  if (wo.z == 0.f || !is_finite(wo) || !is_finite(wi)) return Rgb(0.f);
  switch (b.type) {
    case BsdfType::Diffuse: return bsdf_detail::diffuse_f(b, wo, wi);
    case BsdfType::Conductor: return bsdf_detail::conductor_f(b, wo, wi);
    case BsdfType::Dielectric: return bsdf_detail::dielectric_f(b, wo, wi);
    case BsdfType::CoatedDiffuse: return bsdf_detail::coated_f(b, wo, wi);
    case BsdfType::CoatedConductor: return bsdf_detail::coated_conductor_f(b, wo, wi);
    case BsdfType::ThinDielectric: return Rgb(0.f);  // deltas only
    case BsdfType::DiffuseTransmission: return bsdf_detail::diffuse_transmission_f(b, wo, wi);
    case BsdfType::Hair: return hair_f(bsdf_detail::hair_fiber(b), wo, wi);
    case BsdfType::SubsurfaceExit: return bsdf_detail::subsurface_exit_f(b, wo, wi);
  }
  return Rgb(0.f);
}

// The value next-event estimation uses: bsdf_eval, except that the coated
// BSDFs weigh their layer walk as pbrt-v4's LayeredBxDF::f does (layered.h).
TESSERA_HOST_DEVICE TESSERA_DEVICE_NOINLINE inline Rgb bsdf_eval_light(const BsdfParams& b, const Vec3& wo, const Vec3& wi) {
  if (wo.z == 0.f || !is_finite(wo) || !is_finite(wi)) return Rgb(0.f);
  switch (b.type) {
    case BsdfType::CoatedDiffuse: return bsdf_detail::coated_f(b, wo, wi, bsdf_detail::layered::LayerWeights::Pbrt);
    case BsdfType::CoatedConductor:
      return bsdf_detail::coated_conductor_f(b, wo, wi, bsdf_detail::layered::LayerWeights::Pbrt);
    default: return bsdf_eval(b, wo, wi);
  }
}

TESSERA_HOST_DEVICE TESSERA_DEVICE_NOINLINE inline Float bsdf_pdf(const BsdfParams& b, const Vec3& wo, const Vec3& wi) {
  if (wo.z == 0.f || !is_finite(wo) || !is_finite(wi)) return 0.f;
  switch (b.type) {
    case BsdfType::Diffuse: return bsdf_detail::diffuse_pdf(b, wo, wi);
    case BsdfType::Conductor: return bsdf_detail::conductor_pdf(b, wo, wi);
    case BsdfType::Dielectric: return bsdf_detail::dielectric_pdf(b, wo, wi);
    case BsdfType::CoatedDiffuse: return bsdf_detail::coated_pdf(b, wo, wi);
    case BsdfType::CoatedConductor: return bsdf_detail::coated_conductor_pdf(b, wo, wi);
    case BsdfType::ThinDielectric: return 0.f;
    case BsdfType::DiffuseTransmission: return bsdf_detail::diffuse_transmission_pdf(b, wo, wi);
    case BsdfType::Hair: return hair_pdf(bsdf_detail::hair_fiber(b), wo, wi);
    case BsdfType::SubsurfaceExit: return bsdf_detail::subsurface_exit_pdf(wi);
  }
  return 0.f;
}

// Whether MIS weights at this BSDF use pbrt-v4's stochastic density
// (bsdf_mis_pdf) instead of bsdf_pdf: the coated BSDFs.
TESSERA_HOST_DEVICE inline bool bsdf_mis_estimated(const BsdfParams& b) {
  return b.type == BsdfType::CoatedDiffuse || b.type == BsdfType::CoatedConductor;
}

// The density MIS weighs this BSDF's strategy by. Any function does, as long
// as next-event estimation and BSDF sampling use the same one (their weights
// then sum to 1 for every direction): bsdf_pdf, except for the coated BSDFs,
// where pbrt-v4 weighs by its stochastic LayeredBxDF::PDF, which, since the
// two layered values differ (layered.h), shapes its pictures.
TESSERA_HOST_DEVICE TESSERA_DEVICE_NOINLINE inline Float bsdf_mis_pdf(const BsdfParams& b, const Vec3& wo, const Vec3& wi) {
  if (wo.z == 0.f || !is_finite(wo) || !is_finite(wi)) return 0.f;
  switch (b.type) {
    case BsdfType::CoatedDiffuse: return bsdf_detail::coated_diffuse_pdf_estimate(b, wo, wi);
    case BsdfType::CoatedConductor: return bsdf_detail::coated_conductor_pdf_estimate(b, wo, wi);
    default: return bsdf_pdf(b, wo, wi);
  }
}

TESSERA_HOST_DEVICE TESSERA_DEVICE_NOINLINE inline bool bsdf_sample(const BsdfParams& b, const Vec3& wo, Float uc, Vec2 u, BsdfSample* out) {
  if (wo.z == 0.f || !is_finite(wo)) return false;
  uc = glm::clamp(uc, 0.f, 0x1.fffffep-1f);
  u = glm::clamp(u, Vec2(0.f), Vec2(0x1.fffffep-1f));
  BsdfSample s;
  bool ok = false;
  switch (b.type) {
    case BsdfType::Diffuse: ok = bsdf_detail::diffuse_sample(b, wo, uc, u, &s); break;
    case BsdfType::Conductor: ok = bsdf_detail::conductor_sample(b, wo, uc, u, &s); break;
    case BsdfType::Dielectric: ok = bsdf_detail::dielectric_sample(b, wo, uc, u, &s); break;
    case BsdfType::CoatedDiffuse: ok = bsdf_detail::coated_sample(b, wo, uc, u, &s); break;
    case BsdfType::CoatedConductor: ok = bsdf_detail::coated_conductor_sample(b, wo, uc, u, &s); break;
    case BsdfType::ThinDielectric: ok = bsdf_detail::thin_dielectric_sample(b, wo, uc, &s); break;
    case BsdfType::DiffuseTransmission: ok = bsdf_detail::diffuse_transmission_sample(b, wo, uc, u, &s); break;
    case BsdfType::Hair: ok = bsdf_detail::hair_sample(b, wo, uc, u, &s); break;
    case BsdfType::SubsurfaceExit: ok = bsdf_detail::subsurface_exit_sample(b, wo, u, &s); break;
  }
  // pbrt-v4 BSDF::Sample_f: reject black f, zero pdf and wi in the tangent plane.
  if (!ok || s.wi.z == 0.f || !is_finite(s.wi) || !is_finite(s.f) || is_black(s.f)) return false;
  if (!(s.pdf > 0.f) || !bsdf_detail::finite_f(s.pdf) || !bsdf_detail::finite_f(s.eta) || !(s.eta > 0.f)) return false;
  *out = s;
  return true;
}

// Whether a sampled direction on the wrong side of the flat face for its
// lobe is mirrored back (surface.h, keep_on_lobe_side): every lobe but the
// deltas and hair's, whose sides are those of the round fibre, not of the
// tube's faces (its transmission leaves through the one-way far wall).
TESSERA_HOST_DEVICE inline bool keeps_lobe_side(const BsdfParams& b, uint32_t lobe) {
  return !(lobe & kLobeSpecular) && b.type != BsdfType::Hair;
}

TESSERA_HOST_DEVICE inline uint32_t bsdf_lobes(const BsdfParams& b) {
  switch (b.type) {
    case BsdfType::Diffuse: return is_black(b.reflectance) ? kLobeNone : (kLobeReflection | kLobeDiffuse);
    case BsdfType::Conductor:
      return kLobeReflection | (bsdf_detail::distrib(b).effectively_smooth() ? kLobeSpecular : kLobeGlossy);
    case BsdfType::Dielectric: {
      // pbrt-v4 reports Glossy for a rough eta == 1 interface although it
      // behaves as a specular passthrough; report what it actually does.
      if (bsdf_detail::dielectric_eta(b) == 1.f) return kLobeTransmission | kLobeSpecular;
      return kLobeReflection | kLobeTransmission |
             (bsdf_detail::distrib(b).effectively_smooth() ? kLobeSpecular : kLobeGlossy);
    }
    case BsdfType::DiffuseTransmission:
      return (is_black(b.reflectance) ? kLobeNone : kLobeReflection) |
             (is_black(b.transmittance) ? kLobeNone : kLobeTransmission) |
             (is_black(b.reflectance) && is_black(b.transmittance) ? kLobeNone : kLobeDiffuse);
    case BsdfType::CoatedDiffuse:
      return kLobeReflection | kLobeDiffuse |
             (bsdf_detail::distrib(b).effectively_smooth() ? kLobeSpecular : kLobeGlossy);
    case BsdfType::ThinDielectric: return kLobeReflection | kLobeTransmission | kLobeSpecular;
    case BsdfType::Hair: return kLobeReflection | kLobeTransmission | kLobeGlossy;
    case BsdfType::SubsurfaceExit: return kLobeTransmission | kLobeDiffuse;
    case BsdfType::CoatedConductor: {
      const bool coat_smooth = bsdf_detail::distrib(b).effectively_smooth();
      if (coat_smooth && bsdf_detail::coated_conductor::base_smooth(b)) return kLobeReflection | kLobeSpecular;
      return kLobeReflection | kLobeGlossy | (coat_smooth ? kLobeSpecular : kLobeNone);
    }
  }
  return kLobeNone;
}

}  // namespace tessera
