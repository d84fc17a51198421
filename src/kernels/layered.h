// pbrt-v4's layered BSDF value (LayeredBxDF::f) for "coateddiffuse" and
// "coatedconductor": a dielectric interface (smooth or GGX) over a Lambertian
// or conductor base, a thin non-scattering layer between them (transmittance
// exp(-thickness/|cos|)), two-sided. The value is pbrt-v4's stochastic estimate: a random walk
// between the interfaces with next-event estimation through the exit
// interface, seeded by the two directions so that f(wo, wi) is a pure
// function. Two weightings of its two next-event strategies at the base:
//  * LayerWeights::Consistent: by the densities of the same inside direction.
//    The expectation is the layered BSDF that pbrt-v4's sampling walk
//    (LayeredBxDF::Sample_f) simulates: energy-conserving, reciprocal.
//  * LayerWeights::Pbrt: pbrt-v4's f(), which weighs the exit connection by
//    the density of wi given the inside direction, a different measure. Its
//    weights sum to more than 1 and it comes out 5-15 % above the walk for
//    rough coats (above 1 in albedo for a rough coat over silver).
// pbrt-v4 uses f() for light samples and the walk for BSDF samples, so its
// pictures mix the two: bsdf_eval_light() (next-event estimation) uses
// pbrt-v4's weighting and everything else the consistent one, which
// reproduces pbrt-v4 under both small and large lights.
//
// Included by bsdf_impl.h inside namespace tessera::bsdf_detail; uses the
// dielectric helpers defined there.
#pragma once

namespace layered {

enum class LayerWeights { Consistent, Pbrt };

// One lobe of the dielectric interface, as pbrt-v4 samples it with
// BxDFReflTransFlags::Reflection or ::Transmission. `radiance`: transport
// mode (transmission is divided by eta'^2 only for radiance).
struct LobeSample {
  Vec3 wi{0.f};
  Float f = 0.f;
  Float pdf = 0.f;
};

TESSERA_HOST_DEVICE inline bool interface_sample(const BsdfParams& b, const Vec3& wo, Vec2 u, bool transmission,
                                                 bool radiance, LobeSample* s) {
  const Float eta = dielectric_eta(b);
  if (wo.z == 0.f) return false;
  if (dielectric_is_specular(b)) {
    const Float R = fr_dielectric(cos_theta(wo), eta), T = 1.f - R;
    if (!transmission) {
      if (!(R > 0.f)) return false;
      s->wi = Vec3(-wo.x, -wo.y, wo.z);
      s->f = R / abs_cos_theta(s->wi);
      s->pdf = 1.f;
      return true;
    }
    if (!(T > 0.f)) return false;
    Float etap = 1.f;
    if (!refract(wo, Vec3(0.f, 0.f, 1.f), eta, &etap, &s->wi) || s->wi.z == 0.f) return false;
    s->f = T / abs_cos_theta(s->wi) / (radiance ? sqr(etap) : 1.f);
    s->pdf = 1.f;
    return true;
  }
  const TrowbridgeReitz d = distrib(b);
  const Vec3 wm = d.sample_wm(wo, u);
  const Float dom = glm::dot(wo, wm);
  const Float R = fr_dielectric(dom, eta), T = 1.f - R;
  if (!transmission) {
    if (!(R > 0.f)) return false;
    const Vec3 wi = reflect(wo, wm);
    const Float cc = cos_theta(wi) * cos_theta(wo);
    if (!same_hemisphere(wo, wi) || dom == 0.f || cc == 0.f) return false;
    s->wi = wi;
    s->pdf = d.pdf(wo, wm) / (4.f * fabsf(dom));
    s->f = d.D(wm) * d.G(wo, wi) * R / fabsf(4.f * cc);
    return s->pdf > 0.f;
  }
  if (!(T > 0.f)) return false;
  Vec3 wi;
  Float etap = 1.f;
  if (!refract(wo, wm, eta, &etap, &wi) || same_hemisphere(wo, wi) || wi.z == 0.f) return false;
  const Float dim = glm::dot(wi, wm), denom = sqr(dim + dom / etap), cc = cos_theta(wi) * cos_theta(wo);
  if (denom == 0.f || cc == 0.f) return false;
  s->wi = wi;
  s->pdf = d.pdf(wo, wm) * fabsf(dim) / denom;
  s->f = T * d.D(wm) * d.G(wo, wi) * fabsf(dim * dom / (cc * denom)) / (radiance ? sqr(etap) : 1.f);
  return s->pdf > 0.f && finite_f(s->f);
}

// pbrt-v4 DielectricBxDF::PDF with BxDFReflTransFlags::Transmission: the
// density of the transmission lobe alone (0 for reflection configurations).
TESSERA_HOST_DEVICE inline Float interface_transmission_pdf(const BsdfParams& b, const Vec3& wo, const Vec3& wi) {
  if (dielectric_is_specular(b)) return 0.f;
  Vec3 wm;
  Float etap;
  bool refl;
  if (!dielectric_half_vector(dielectric_eta(b), wo, wi, &wm, &etap, &refl) || refl) return 0.f;
  const Float R = fr_dielectric(glm::dot(wo, wm), dielectric_eta(b));
  if (!(1.f - R > 0.f)) return 0.f;
  const Float denom = sqr(glm::dot(wi, wm) + glm::dot(wo, wm) / etap);
  if (denom == 0.f) return 0.f;
  return finite_or_zero(distrib(b).pdf(wo, wm) * fabsf(glm::dot(wi, wm)) / denom);
}

// pbrt-v4 DielectricBxDF::PDF with BxDFReflTransFlags::Reflection: the
// whole reflection lobe's density (not scaled by the Fresnel reflectance).
TESSERA_HOST_DEVICE inline Float interface_reflection_pdf(const BsdfParams& b, const Vec3& wo, const Vec3& wi) {
  if (dielectric_is_specular(b) || !same_hemisphere(wo, wi)) return 0.f;
  Vec3 wm = wo + wi;
  if (len2(wm) == 0.f) return 0.f;
  wm = face_forward_z(glm::normalize(wm));
  if (glm::dot(wm, wi) * wi.z < 0.f || glm::dot(wm, wo) * wo.z < 0.f) return 0.f;  // back-facing microfacet
  const Float dom = fabsf(glm::dot(wo, wm));
  return dom > 0.f ? finite_or_zero(distrib(b).pdf(wo, wm) / (4.f * dom)) : 0.f;
}

TESSERA_HOST_DEVICE inline Float transmittance(Float dz, const Vec3& w) {
  if (fabsf(dz) <= 1.17549435e-38f) return 1.f;
  return expf(-fabsf(dz / w.z));
}

// The random numbers of one evaluation: a pure function of (wo, wi).
TESSERA_HOST_DEVICE inline Rng rng_for(const Vec3& wo, const Vec3& wi) {
  Rng r;
  r.set_sequence(hash_vec3(wo), hash_vec3(wi));
  return r;
}

// The base layers the walk below needs: the BSDF value, its density, and a
// reflection sample (local frame, wo and wi pointing away from the base).
struct DiffuseBase {
  Rgb R;
  TESSERA_HOST_DEVICE bool specular() const { return false; }
  TESSERA_HOST_DEVICE Rgb f(const Vec3& wo, const Vec3& wi) const {
    return same_hemisphere(wo, wi) ? R * kInvPi : Rgb(0.f);
  }
  TESSERA_HOST_DEVICE Float pdf(const Vec3& wo, const Vec3& wi) const {
    return same_hemisphere(wo, wi) ? cosine_hemisphere_pdf(abs_cos_theta(wi)) : 0.f;
  }
  TESSERA_HOST_DEVICE bool sample(const Vec3& wo, Vec2 u, Vec3* wi, Rgb* f, Float* pdf) const {
    Vec3 w = sample_cosine_hemisphere(u);
    if (wo.z < 0.f) w.z = -w.z;
    *pdf = cosine_hemisphere_pdf(abs_cos_theta(w));
    if (!(*pdf > 0.f) || w.z == 0.f || is_black(R)) return false;
    *wi = w;
    *f = R * kInvPi;
    return true;
  }
};

// pbrt-v4's CoatedConductor base: the conductor's eta and k relative to the
// coat (divided by the coat's index), its own roughness.
struct ConductorBase {
  BsdfParams p;
  TESSERA_HOST_DEVICE static ConductorBase under_coat(const BsdfParams& coat) {
    ConductorBase c;
    c.p = coat;
    c.p.type = BsdfType::Conductor;
    c.p.alpha_x = coat.base_alpha_x;
    c.p.alpha_y = coat.base_alpha_y;
    c.p.eta = coat.eta / dielectric_eta(coat);
    c.p.k = coat.k / dielectric_eta(coat);
    return c;
  }
  TESSERA_HOST_DEVICE bool specular() const { return distrib(p).effectively_smooth(); }
  TESSERA_HOST_DEVICE Rgb f(const Vec3& wo, const Vec3& wi) const { return conductor_f(p, wo, wi); }
  TESSERA_HOST_DEVICE Float pdf(const Vec3& wo, const Vec3& wi) const { return conductor_pdf(p, wo, wi); }
  TESSERA_HOST_DEVICE bool sample(const Vec3& wo, Vec2 u, Vec3* wi, Rgb* f, Float* pdf) const {
    BsdfSample s;
    if (!conductor_sample(p, wo, 0.f, u, &s) || !(s.pdf > 0.f) || s.wi.z == 0.f) return false;
    *wi = s.wi;
    *f = s.f;
    *pdf = s.pdf;
    return true;
  }
};

}  // namespace layered

// LayeredBxDF<DielectricBxDF, Base, twoSided = true>::f for reflection (wo
// and wi in the same hemisphere; neither coated BSDF transmits). b is the
// coat (its roughness, ior, and the layer's thickness, maxdepth, nsamples).
// Out of line on the GPU (device.h), like layered_pdf_estimate: a long walk
// that only coated surfaces take, once per BSDF entry point that reaches it.
template <class Base>
TESSERA_HOST_DEVICE TESSERA_DEVICE_NOINLINE inline Rgb layered_f(const BsdfParams& b, const Base& base, Vec3 wo, Vec3 wi,
                                                                 layered::LayerWeights weights) {
  if (!same_hemisphere(wo, wi)) return Rgb(0.f);
  if (wo.z < 0.f) {  // two-sided
    wo = -wo;
    wi = -wi;
  }
  const Float thickness = glm::max(b.thickness, 1.17549435e-38f);
  const uint32_t n_samples = b.layer_samples > 0 ? b.layer_samples : 1;
  const bool top_specular = dielectric_is_specular(b);
  const bool base_specular = base.specular();
  const bool scattering = !is_black(b.layer_albedo);
  // Reflection at the entrance (top) interface: deterministic.
  Rgb f = top_specular ? Rgb(0.f) : Rgb(static_cast<Float>(n_samples) * dielectric_f(b, wo, wi).x);
  Rng rng = layered::rng_for(wo, wi);
  auto r = [&rng]() { return rng.uniform(); };
  for (uint32_t s = 0; s < n_samples; ++s) {
    // Into the layer through the top, and the "virtual light" path from wi
    // into the layer (importance transport: no 1/eta^2).
    layered::LobeSample wos, wis;
    { Vec2 u(r(), r()); if (!layered::interface_sample(b, wo, u, true, true, &wos)) continue; }
    { Vec2 u(r(), r()); if (!layered::interface_sample(b, wi, u, true, false, &wis)) continue; }
    Rgb beta(wos.f * abs_cos_theta(wos.wi) / wos.pdf);
    Vec3 w = wos.wi;
    Float z = thickness;  // the top is the exit: wo and wi are on its side
    for (uint32_t depth = 0; depth < b.layer_max_depth; ++depth) {
      // Russian roulette, as pbrt-v4.
      const Float max_beta = glm::max(beta.x, glm::max(beta.y, beta.z));
      if (depth > 3 && max_beta < 0.25f) {
        const Float q = glm::max(0.f, 1.f - max_beta);
        if (r() < q) break;
        beta /= 1.f - q;
      }
      if (!scattering) {
        // Across the clear layer to the other interface.
        z = z == thickness ? 0.f : thickness;
        beta *= layered::transmittance(thickness, w);
      } else {
        // A free flight in the unit-extinction medium (pbrt-v4): a
        // scattering event inside the layer, or the next interface.
        const Float dz = -glm::log(1.f - glm::min(r(), 0x1.fffffep-1f)) * fabsf(w.z);
        const Float zp = w.z > 0.f ? z + dz : z - dz;
        if (zp == z) continue;
        if (0.f < zp && zp < thickness) {
          // Next-event estimation out through the top along wis...
          const Vec3 to_light = -wis.wi;
          Float wt = 1.f;
          if (!top_specular) wt = power_heuristic(wis.pdf, henyey_greenstein(glm::dot(-w, to_light), b.layer_g));
          f += beta * b.layer_albedo * henyey_greenstein(glm::dot(-w, to_light), b.layer_g) * wt *
               layered::transmittance(zp - thickness, wis.wi) * (wis.f / wis.pdf);
          // ...then a new direction from the phase function.
          Float phase_pdf = 0.f;
          const Vec3 wp = sample_henyey_greenstein(-w, b.layer_g, Vec2(r(), r()), &phase_pdf);
          if (!(phase_pdf > 0.f) || wp.z == 0.f) continue;
          beta *= b.layer_albedo;  // exact sampling: p / pdf = 1
          w = wp;
          z = zp;
          if (w.z > 0.f && !top_specular) {
            // ...and out through the rough top along it.
            const Float f_exit = dielectric_f(b, -w, wi).x;
            if (f_exit > 0.f) {
              const Float exit_pdf = weights == layered::LayerWeights::Consistent
                                         ? layered::interface_transmission_pdf(b, wi, -w)
                                         : layered::interface_transmission_pdf(b, -w, wi);
              f += beta * layered::transmittance(zp - thickness, w) * f_exit * power_heuristic(phase_pdf, exit_pdf);
            }
          }
          continue;
        }
        z = glm::clamp(zp, 0.f, thickness);
      }
      const bool at_top = z == thickness;
      if (at_top) {
        // Internal reflection at the exit (top) interface.
        layered::LobeSample bs;
        Vec2 u(r(), r());
        if (!layered::interface_sample(b, -w, u, false, true, &bs)) break;
        beta *= bs.f * abs_cos_theta(bs.wi) / bs.pdf;
        w = bs.wi;
      } else {
        // At the base: next-event estimation along wis (not for a mirror base)...
        if (!base_specular) {
          const Vec3 to_light = -wis.wi;
          Float wt = 1.f;
          if (!top_specular) wt = power_heuristic(wis.pdf, base.pdf(-w, to_light));
          f += beta * base.f(-w, to_light) * abs_cos_theta(wis.wi) * wt * layered::transmittance(thickness, wis.wi) *
               (wis.f / wis.pdf);
        }
        // ...then a new direction from the base.
        Vec3 wi_base;
        Rgb f_base;
        Float pdf = 0.f;
        if (!base.sample(-w, Vec2(r(), r()), &wi_base, &f_base, &pdf)) break;
        beta *= f_base * abs_cos_theta(wi_base) / pdf;
        w = wi_base;
        if (!top_specular) {
          // ...and through the rough top along the base's own sample.
          const Float f_exit = dielectric_f(b, -w, wi).x;
          if (f_exit > 0.f) {
            Float wt = 1.f;
            // The other strategy's density of this direction: the virtual
            // light's sample from wi reaching -w (pbrt-v4: of wi given -w).
            if (!base_specular)
              wt = power_heuristic(pdf, weights == layered::LayerWeights::Consistent
                                            ? layered::interface_transmission_pdf(b, wi, -w)
                                            : layered::interface_transmission_pdf(b, -w, wi));
            f += beta * layered::transmittance(thickness, w) * f_exit * wt;
          }
        }
      }
    }
  }
  return finite_or_zero(f / static_cast<Float>(n_samples));
}

// pbrt-v4's LayeredBxDF::PDF for reflection: a stochastic estimate of the
// walk's density (the entrance reflection lobe plus one TRT term per
// sample), mixed 9:1 with the uniform sphere's density. pbrt-v4 weighs MIS
// with it, and so with it decides how its pictures blend the two layered
// values (see the file's opening comment): the same estimator, not only its
// mean, reproduces them. Seeded by (wi, wo), as pbrt-v4 seeds it, so it is a
// pure function of the two directions, independent of layered_f's numbers.
template <class Base>
TESSERA_HOST_DEVICE TESSERA_DEVICE_NOINLINE inline Float layered_pdf_estimate(const BsdfParams& b, const Base& base, Vec3 wo,
                                                                            Vec3 wi) {
  constexpr Float kUniformSphere = 1.f / (4.f * kPi);
  if (!same_hemisphere(wo, wi)) return 0.1f * kUniformSphere;  // an opaque base: no TT term
  if (wo.z < 0.f) {  // two-sided
    wo = -wo;
    wi = -wi;
  }
  const uint32_t n_samples = b.layer_samples > 0 ? b.layer_samples : 1;
  const bool top_specular = dielectric_is_specular(b);
  Float pdf_sum = static_cast<Float>(n_samples) * layered::interface_reflection_pdf(b, wo, wi);
  Rng rng = layered::rng_for(wi, wo);
  auto r = [&rng]() { return rng.uniform(); };
  for (uint32_t s = 0; s < n_samples; ++s) {
    layered::LobeSample wos, wis;
    { Vec2 u(r(), r()); if (!layered::interface_sample(b, wo, u, true, true, &wos)) continue; }
    { Vec2 u(r(), r()); if (!layered::interface_sample(b, wi, u, true, false, &wis)) continue; }
    if (top_specular) {
      pdf_sum += base.pdf(-wos.wi, -wis.wi);
      continue;
    }
    Vec3 wi_base;
    Rgb f_base;
    Float base_pdf = 0.f;
    if (!base.sample(-wos.wi, Vec2(r(), r()), &wi_base, &f_base, &base_pdf)) continue;
    if (base.specular()) {
      pdf_sum += dielectric_pdf(b, -wi_base, wi);
    } else {
      // Both ends' samples, combined by the power heuristic (pbrt-v4).
      const Float r_pdf = base.pdf(-wos.wi, -wis.wi);
      pdf_sum += power_heuristic(wis.pdf, r_pdf) * r_pdf;
      const Float t_pdf = dielectric_pdf(b, -wi_base, wi);
      pdf_sum += power_heuristic(base_pdf, t_pdf) * t_pdf;
    }
  }
  return finite_or_zero(0.1f * kUniformSphere + 0.9f * pdf_sum / static_cast<Float>(n_samples));
}

// coateddiffuse: b.reflectance is the base's albedo.
TESSERA_HOST_DEVICE inline Rgb coated_diffuse_layered_f(const BsdfParams& b, const Vec3& wo, const Vec3& wi,
                                                        layered::LayerWeights weights = layered::LayerWeights::Consistent) {
  return layered_f(b, layered::DiffuseBase{glm::clamp(b.reflectance, Rgb(0.f), Rgb(1.f))}, wo, wi, weights);
}

// coatedconductor: b.eta / b.k are the conductor's (relative to the outside),
// b.base_alpha_* its roughness.
TESSERA_HOST_DEVICE inline Rgb coated_conductor_layered_f(const BsdfParams& b, const Vec3& wo, const Vec3& wi,
                                                          layered::LayerWeights weights = layered::LayerWeights::Consistent) {
  return layered_f(b, layered::ConductorBase::under_coat(b), wo, wi, weights);
}

TESSERA_HOST_DEVICE inline Float coated_diffuse_pdf_estimate(const BsdfParams& b, const Vec3& wo, const Vec3& wi) {
  return layered_pdf_estimate(b, layered::DiffuseBase{glm::clamp(b.reflectance, Rgb(0.f), Rgb(1.f))}, wo, wi);
}

TESSERA_HOST_DEVICE inline Float coated_conductor_pdf_estimate(const BsdfParams& b, const Vec3& wo, const Vec3& wi) {
  return layered_pdf_estimate(b, layered::ConductorBase::under_coat(b), wo, wi);
}
