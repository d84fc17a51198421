// pbrt-v4's "coatedconductor": a dielectric coat over a conductor. The value
// f(wo, wi) is pbrt-v4's layered estimate (layered.h) with the conductor as
// the base. Directions are sampled from a closed-form proposal whose density
// is exact (so MIS and guided mixtures stay exact; f / q has the expectation
// of pbrt-v4's value):
//
//   q = p_coat * coat's GGX reflection + p_base * GGX reflection of the
//       effective (coat + conductor) roughness + 0.1 * cos(wi) / pi
//
// the last term a defensive lobe that covers every direction the layered
// walk can reach. A smooth coat's mirror reflection is a delta with its exact
// weight F(cos_o) (pbrt's layered f() excludes it too); a smooth coat over a
// smooth conductor is a single delta whose weight is the closed form of the
// interreflection series (the limit of pbrt-v4's walk, which stops after
// "maxdepth" bounces: a little brighter at grazing angles). Two-sided;
// reflection only.
//
// Included by bsdf_impl.h inside namespace tessera::bsdf_detail, after layered.h.
#pragma once

namespace coated_conductor {

constexpr Float kDefensive = 0.1f;

// Roughness of the light that went through the coat to the base and back:
// the base's lobe widens by the coat's index on the way out, and a rough coat
// spreads it on the way in and out.
TESSERA_HOST_DEVICE inline TrowbridgeReitz effective_distrib(const BsdfParams& b) {
  const Float eta = dielectric_eta(b);
  auto combine = [&](Float coat, Float base) { return glm::min(1.f, glm::sqrt(2.f * coat * coat + sqr(eta * base))); };
  return TrowbridgeReitz(combine(b.alpha_x, b.base_alpha_x), combine(b.alpha_y, b.base_alpha_y));
}

TESSERA_HOST_DEVICE inline bool base_smooth(const BsdfParams& b) {
  return TrowbridgeReitz(b.base_alpha_x, b.base_alpha_y).effectively_smooth();
}

// Share of the coat's lobe: its Fresnel reflectance against what the base
// returns through the coat (the conductor's normal-incidence reflectance).
TESSERA_HOST_DEVICE inline Float p_coat(const BsdfParams& b, Float cos_o) {
  const Float eta = dielectric_eta(b);
  const Float Fo = fr_dielectric(cos_o, eta);
  const Float Rb = luminance(fr_complex(1.f, b.eta / eta, b.k / eta));
  const Float denom = Fo + sqr(1.f - Fo) * Rb;
  const Float p = denom > 0.f ? Fo / denom : 0.5f;
  return (1.f - kDefensive) * glm::clamp(p, 0.05f, 0.95f);
}

TESSERA_HOST_DEVICE inline Float ggx_reflection_pdf(const TrowbridgeReitz& d, const Vec3& wo, const Vec3& wi) {
  Vec3 wm = wo + wi;
  if (len2(wm) == 0.f) return 0.f;
  wm = glm::normalize(wm);
  const Float dom = glm::dot(wo, wm);
  return dom > 0.f ? d.pdf(wo, wm) / (4.f * dom) : 0.f;
}

// The proposal's density for wo, wi both with z > 0 (the delta parts excluded).
TESSERA_HOST_DEVICE inline Float pdf_upper(const BsdfParams& b, const Vec3& wo, const Vec3& wi) {
  if (!(wo.z > 0.f) || !(wi.z > 0.f)) return 0.f;
  const TrowbridgeReitz coat = distrib(b);
  if (coat.effectively_smooth() && base_smooth(b)) return 0.f;
  const Float pc = p_coat(b, wo.z);
  Float pdf = kDefensive * cosine_hemisphere_pdf(wi.z);
  pdf += (1.f - kDefensive - pc) * ggx_reflection_pdf(effective_distrib(b), wo, wi);
  if (!coat.effectively_smooth()) pdf += pc * ggx_reflection_pdf(coat, wo, wi);
  return finite_or_zero(pdf);
}

// A smooth coat over a smooth conductor: all light leaves in the mirror
// direction, with R + (1 - R)^2 Rb T^2 / (1 - R Rb T^2) (R the coat's
// Fresnel reflectance, equal inside and out; Rb the conductor's at the
// refracted angle; T the layer's transmittance one way).
TESSERA_HOST_DEVICE inline Rgb mirror_series(const BsdfParams& b, Float cos_o) {
  const Float eta = dielectric_eta(b);
  const Float R = fr_dielectric(cos_o, eta);
  const Float sin2_t = (1.f - cos_o * cos_o) / (eta * eta);
  const Float cos_t = safe_sqrt(1.f - sin2_t);
  const Rgb Rb = fr_complex(cos_t, b.eta / eta, b.k / eta);
  const Float T = cos_t > 0.f ? expf(-glm::max(b.thickness, 0.f) / cos_t) : 0.f;
  const Rgb loop = R * Rb * (T * T);
  return R + sqr(1.f - R) * Rb * (T * T) / (Rgb(1.f) - loop);
}

}  // namespace coated_conductor

TESSERA_HOST_DEVICE inline Rgb coated_conductor_f(const BsdfParams& b, const Vec3& wo, const Vec3& wi,
                                                  layered::LayerWeights weights = layered::LayerWeights::Consistent) {
  if (distrib(b).effectively_smooth() && coated_conductor::base_smooth(b)) return Rgb(0.f);
  return coated_conductor_layered_f(b, wo, wi, weights);
}

TESSERA_HOST_DEVICE inline Float coated_conductor_pdf(const BsdfParams& b, const Vec3& wo, const Vec3& wi) {
  if (!same_hemisphere(wo, wi)) return 0.f;
  const bool flip = wo.z < 0.f;
  return coated_conductor::pdf_upper(b, flip_to_upper(wo, flip), flip_to_upper(wi, flip));
}

TESSERA_HOST_DEVICE inline bool coated_conductor_sample(const BsdfParams& b, const Vec3& wo_in, Float uc, Vec2 u,
                                                        BsdfSample* s) {
  const bool flip = wo_in.z < 0.f;
  const Vec3 wo = flip_to_upper(wo_in, flip);
  if (!(wo.z > 0.f)) return false;
  const TrowbridgeReitz coat = distrib(b);
  s->eta = 1.f;
  if (coat.effectively_smooth() && coated_conductor::base_smooth(b)) {
    s->wi = flip_to_upper(Vec3(-wo.x, -wo.y, wo.z), flip);
    s->f = coated_conductor::mirror_series(b, wo.z) / wo.z;
    s->pdf = 1.f;
    s->lobe = kLobeReflection | kLobeSpecular;
    return true;
  }
  const Float pc = coated_conductor::p_coat(b, wo.z);
  Vec3 wi;
  if (uc < pc && coat.effectively_smooth()) {
    s->wi = flip_to_upper(Vec3(-wo.x, -wo.y, wo.z), flip);
    s->f = Rgb(fr_dielectric(wo.z, dielectric_eta(b)) / wo.z);
    s->pdf = pc;
    s->lobe = kLobeReflection | kLobeSpecular;
    return true;
  }
  if (uc < pc) {
    wi = reflect(wo, coat.sample_wm(wo, u));
  } else if (uc < 1.f - coated_conductor::kDefensive) {
    wi = reflect(wo, coated_conductor::effective_distrib(b).sample_wm(wo, u));
  } else {
    wi = sample_cosine_hemisphere(u);
  }
  if (!(wi.z > 0.f)) return false;
  s->wi = flip_to_upper(wi, flip);
  s->f = coated_conductor_layered_f(b, wo_in, s->wi);
  s->pdf = coated_conductor::pdf_upper(b, wo, wi);
  s->lobe = kLobeReflection | kLobeGlossy;
  return true;
}
