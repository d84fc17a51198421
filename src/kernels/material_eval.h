// Turning a scene Material into BsdfParams at a hit (textures, mix choice).
#pragma once

#include "bsdf.h"
#include "effects.h"
#include "rng.h"
#include "surface.h"
#include "texture_eval.h"

namespace tessera {

// pbrt-v4 picks a mix component with a hash of the hit, not with a sampler
// dimension, so the choice is deterministic per point and direction.
TESSERA_HOST_DEVICE inline Float mix_hash_float(const Vec3& p, const Vec3& wo, int32_t a, int32_t b) {
  uint64_t h = mix_bits(hash_vec3(p) ^ (hash_vec3(wo) * 0xd1b54a32d192ed03ull));
  h = mix_bits(h ^ (static_cast<uint64_t>(static_cast<uint32_t>(a)) << 32) ^ static_cast<uint32_t>(b));
  return static_cast<Float>(h >> 40) * 0x1p-24f;
}

// The material a hit sees: a mix resolved to one of its components (a pure
// function of the hit and wo, so camera paths and shadow rays agree).
template <uint32_t Spec>
TESSERA_HOST_DEVICE inline const Material* resolve_material(const SceneView& s, int32_t material, const SurfaceHit& h,
                                                            const Vec3& wo) {
  const Material* m = &s.materials[material];
  for (int guard = 0; m->type == MaterialType::Mix && guard < 16; ++guard) {
    Float amount = (Spec & kSpecTextures) ? eval_slot(s, m->amount, texture_point(h)).x : m->amount.value.x;
    int32_t pick;
    if (amount <= 0.f) pick = m->mix[0];  // pbrt-v4 MixMaterial::ChooseMaterial
    else if (amount >= 1.f) pick = m->mix[1];
    else pick = amount < mix_hash_float(h.p, wo, m->mix[0], m->mix[1]) ? m->mix[0] : m->mix[1];
    m = &s.materials[pick];
  }
  // The loader rejects cycles, so only absurdly deep nesting can remain a Mix.
  return m->type == MaterialType::Mix ? &s.materials[0] : m;
}

// Returns false for an "interface" material: the surface only bounds a medium
// and the ray continues through it.
//
// In spectral mode (wl non-null) colours become values at the path's
// wavelengths: reflectances as albedo spectra, conductors' eta and k as
// unbounded spectra (spectral.h).
// GGX alphas from roughness textures, remapped as pbrt-v4's RoughnessToAlpha
// when the material asks.
TESSERA_HOST_DEVICE inline void textured_alpha(const SceneView& s, const Material& m, const TextureSlot& u,
                                               const TextureSlot& v, const SurfaceHit& h, Float* alpha_x, Float* alpha_y) {
  Float ru = eval_slot(s, u, texture_point(h)).x, rv = eval_slot(s, v, texture_point(h)).x;
  ru = ru > 0.f && ru < 1e30f ? ru : 0.f;  // NaN, Inf or negative texels: smooth
  rv = rv > 0.f && rv < 1e30f ? rv : 0.f;
  *alpha_x = m.remap_roughness ? glm::sqrt(ru) : ru;
  *alpha_y = m.remap_roughness ? glm::sqrt(rv) : rv;
}

// A coated material's layer medium, clamped as pbrt-v4 clamps it (albedo
// to [0, 1], g to [-1, 1]: here just inside). Out of line on the GPU
// (device.h), as hair_params: rare materials.
template <uint32_t Spec>
TESSERA_HOST_DEVICE TESSERA_DEVICE_NOINLINE inline void layer_medium(const SceneView& s, const Material& m,
                                                                     const SurfaceHit& h, const Wavelengths* wl,
                                                                     BsdfParams* b) {
  const Rgb albedo = (Spec & kSpecTextures) ? eval_slot(s, m.layer_albedo, texture_point(h)) : m.layer_albedo.value;
  const Float g = (Spec & kSpecTextures) ? eval_slot(s, m.layer_g, texture_point(h)).x : m.layer_g.value.x;
  b->layer_albedo = glm::clamp(spectral_albedo(s.spectral, wl, albedo), Rgb(0.f), Rgb(1.f));
  // pbrt-v4 clamps to [-1, 1]; at +-1 its Henyey-Greenstein is 0 / 0, so a
  // hair inside (NaN: isotropic).
  constexpr Float kMaxG = 0.999f;
  b->layer_g = g >= -kMaxG && g <= kMaxG ? g : (g > kMaxG ? kMaxG : (g < -kMaxG ? -kMaxG : 0.f));
}

// pbrt-v4's HairMaterial at a hit: roughness clamped to [0, 1] (hair.h
// keeps it above 0.01), absorption from sigma_a, the colour (refl) or the
// melanins, each read per wavelength in spectral transport.
template <uint32_t Spec>
TESSERA_HOST_DEVICE TESSERA_DEVICE_NOINLINE inline void hair_params(const SceneView& s, const Material& m,
                                                                    const SurfaceHit& h, const Rgb& refl,
                                                                    const Wavelengths* wl, BsdfParams* b) {
  auto value = [&](const TextureSlot& slot) {
    return (Spec & kSpecTextures) ? eval_slot(s, slot, texture_point(h)).x : slot.value.x;
  };
  b->type = BsdfType::Hair;
  b->hair_beta_m = glm::clamp(value(m.beta_m), 0.f, 1.f);
  b->hair_beta_n = glm::clamp(value(m.beta_n), 0.f, 1.f);
  b->hair_alpha = value(m.hair_alpha);
  switch (m.hair_absorption) {
    case HairAbsorption::SigmaA: {
      const Rgb sigma = (Spec & kSpecTextures) ? eval_slot(s, m.hair_sigma_a, texture_point(h)) : m.hair_sigma_a.value;
      b->hair_sigma_a = glm::max(spectral_unbounded(s.spectral, wl, sigma), Rgb(0.f));
      break;
    }
    case HairAbsorption::Reflectance:
      b->hair_sigma_a = hair_sigma_a_from_reflectance(
          glm::clamp(spectral_albedo(s.spectral, wl, refl), Rgb(0.f), Rgb(1.f)), b->hair_beta_n);
      break;
    case HairAbsorption::Melanin:
      b->hair_sigma_a = glm::max(
          spectral_unbounded(s.spectral, wl,
                             hair_sigma_a_from_concentration(glm::max(value(m.eumelanin), 0.f),
                                                             glm::max(value(m.pheomelanin), 0.f))),
          Rgb(0.f));
      break;
  }
}

template <uint32_t Spec>
TESSERA_HOST_DEVICE inline bool resolve_bsdf(const SceneView& s, int32_t material, const SurfaceHit& h, const Vec3& wo,
                                             BsdfParams* out, Wavelengths* wl = nullptr) {
  const Material* m = &s.materials[material];
  if constexpr ((Spec & kSpecNonDiffuse) != 0) {
    m = resolve_material<Spec>(s, material, h, wo);
    if (m->type == MaterialType::Interface) return false;
  }
  Rgb refl = (Spec & kSpecTextures) ? eval_slot(s, m->reflectance, texture_point(h)) : m->reflectance.value;
  BsdfParams b;
  b.alpha_x = m->alpha_x;
  b.alpha_y = m->alpha_y;
  b.bump = m->bump;
  b.normal_map = m->normal_map;
  if ((Spec & kSpecTextures) && m->textured_roughness)
    textured_alpha(s, *m, m->roughness_u, m->roughness_v, h, &b.alpha_x, &b.alpha_y);
  b.ior = m->ior;
  if (wl && m->ior_spectrum >= 0) {
    // Dispersion: the index at the one wavelength the path goes on with
    // (spectral.h), picked by a hash of the hit like a mix's component.
    const int32_t c = dispersion_channel(*wl, mix_hash_float(h.p, wo, material, 0x6469));
    b.ior = sample_table(s.spectra + m->ior_spectrum * kSpectralSamples, 1, wl->lambda[c]);
  }
  switch (m->type) {
    case MaterialType::Conductor:
    case MaterialType::CoatedConductor:
      b.type = m->type == MaterialType::Conductor ? BsdfType::Conductor : BsdfType::CoatedConductor;
      if (m->conductor_from_reflectance) {
        // pbrt-v4: eta = 1 and k chosen so that normal-incidence reflectance is r.
        Rgb r = glm::clamp(spectral_albedo(s.spectral, wl, refl), Rgb(0.f), Rgb(0.9999f));
        b.eta = Rgb(1.f);
        b.k = 2.f * glm::sqrt(r) / glm::sqrt(Rgb(1.f) - r);
      } else {
        b.eta = wl && m->eta_spectrum >= 0 ? sample_spectrum(s.spectra + m->eta_spectrum * kSpectralSamples, *wl)
                                           : spectral_unbounded(s.spectral, wl, m->eta);
        b.k = wl && m->k_spectrum >= 0 ? sample_spectrum(s.spectra + m->k_spectrum * kSpectralSamples, *wl)
                                       : spectral_unbounded(s.spectral, wl, m->k);
      }
      if (m->type == MaterialType::CoatedConductor) {
        b.base_alpha_x = m->base_alpha_x;
        b.base_alpha_y = m->base_alpha_y;
        if ((Spec & kSpecTextures) && m->textured_base_roughness)
          textured_alpha(s, *m, m->base_roughness_u, m->base_roughness_v, h, &b.base_alpha_x, &b.base_alpha_y);
        b.thickness = m->thickness;
        b.layer_max_depth = m->layer_max_depth;
        b.layer_samples = m->layer_samples;
        // A scattering layer, except between a smooth coat and a smooth
        // conductor (the loader warns): there the value would count only
        // light leaving straight from a scattering event, while light that
        // scatters and leaves by the mirrors belongs to no lobe we sample.
        if (!(TrowbridgeReitz(b.alpha_x, b.alpha_y).effectively_smooth() &&
              TrowbridgeReitz(b.base_alpha_x, b.base_alpha_y).effectively_smooth()))
          layer_medium<Spec>(s, *m, h, wl, &b);
      }
      break;
    case MaterialType::Dielectric:
      b.type = BsdfType::Dielectric;
      break;
    case MaterialType::ThinDielectric:
      b.type = BsdfType::ThinDielectric;
      break;
    case MaterialType::DiffuseTransmission: {
      b.type = BsdfType::DiffuseTransmission;
      const Rgb t = (Spec & kSpecTextures) ? eval_slot(s, m->transmittance, texture_point(h)) : m->transmittance.value;
      // pbrt-v4 scales the spectra, then clamps.
      b.reflectance = glm::clamp(m->scale * spectral_albedo(s.spectral, wl, refl), Rgb(0.f), Rgb(1.f));
      b.transmittance = glm::clamp(m->scale * spectral_albedo(s.spectral, wl, t), Rgb(0.f), Rgb(1.f));
      b.ior = 1.f;  // light passes straight through: no refraction, no eta^2 scaling
      break;
    }
    case MaterialType::CoatedDiffuse:
      b.type = BsdfType::CoatedDiffuse;
      b.reflectance = spectral_albedo(s.spectral, wl, refl);
      layer_medium<Spec>(s, *m, h, wl, &b);
      b.thickness = m->thickness;
      b.layer_max_depth = m->layer_max_depth;
      b.layer_samples = m->layer_samples;
      break;
    case MaterialType::Hair:
      hair_params<Spec>(s, *m, h, refl, wl, &b);
      break;
    case MaterialType::Subsurface:
      // Outside: the boundary's dielectric; from inside (a random walk
      // reaching it): the lobe the walk leaves by.
      if (glm::dot(wo, h.ng) >= 0.f) {
        b.type = BsdfType::Dielectric;
      } else {
        b.type = BsdfType::SubsurfaceExit;
        b.exit_norm = m->exit_norm;
      }
      break;
    default:
      b.type = BsdfType::Diffuse;
      b.reflectance = spectral_albedo(s.spectral, wl, refl);
      break;
  }
  *out = b;
  return true;
}

}  // namespace tessera
