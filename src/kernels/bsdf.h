// BSDFs evaluated in the local shading frame (z = shading normal), pbrt-v4
// conventions: wo and wi both point away from the surface, f() excludes the
// cosine, pdfs are per unit solid angle, transmission is scaled for radiance
// transport (divided by eta^2). Dispatch is an enum switch: no virtual calls.
#pragma once

#include "vecmath.h"

namespace tessera {

enum class BsdfType : uint32_t {
  Diffuse = 0, Conductor, Dielectric, CoatedDiffuse, DiffuseTransmission, CoatedConductor, ThinDielectric, Hair,
  SubsurfaceExit
};

// Lobe flags, combinable.
enum BsdfLobe : uint32_t {
  kLobeNone = 0,
  kLobeReflection = 1u << 0,
  kLobeTransmission = 1u << 1,
  kLobeDiffuse = 1u << 2,
  kLobeGlossy = 1u << 3,
  kLobeSpecular = 1u << 4,
};

// A BSDF with every texture already evaluated at the hit point.
struct BsdfParams {
  BsdfType type = BsdfType::Diffuse;
  Rgb reflectance{0.5f};  // Diffuse, CoatedDiffuse and DiffuseTransmission albedo, in [0,1]
  Rgb transmittance{0.f}; // DiffuseTransmission, in [0,1]
  Rgb eta{1.f};           // Conductor, CoatedConductor's base: real part of the complex IOR, per channel
  Rgb k{0.f};             // ... imaginary part
  Float ior = 1.5f;       // Dielectric / CoatedDiffuse and CoatedConductor coating: n_inside / n_outside
  Float alpha_x = 0.f;    // GGX (Trowbridge-Reitz) roughness, already remapped;
  Float alpha_y = 0.f;    // both below kSmoothAlpha means perfectly smooth (coated BSDFs: the coat's)
  Float base_alpha_x = 0.f, base_alpha_y = 0.f;  // CoatedConductor: the conductor's GGX roughness
  int32_t bump = -1;      // the material's bump texture (applied by the integrator to the shading normal)
  int32_t normal_map = -1;  // the material's normal map image (likewise)
  // The coated BSDFs' layer (pbrt-v4 "thickness", "maxdepth", "nsamples").
  Float thickness = 0.01f;
  uint32_t layer_max_depth = 10;
  uint32_t layer_samples = 1;
  // The layer's scattering medium (pbrt-v4 "albedo", "g"): black, the layer
  // only absorbs (exp(-thickness / |cos|)); otherwise a medium of unit
  // extinction with this single-scattering albedo and Henyey-Greenstein g.
  Rgb layer_albedo{0.f};
  Float layer_g = 0.f;
  // Hair (hair.h; its index is ior): absorption per unit fibre radius,
  // longitudinal and azimuthal roughness, the scales' tilt in degrees. Its
  // frame has x along the fibre and z the tube's round normal.
  Rgb hair_sigma_a{0.f};
  Float hair_beta_m = 0.3f, hair_beta_n = 0.3f, hair_alpha = 2.f;
  // SubsurfaceExit: where a random walk inside a subsurface material meets
  // its boundary and leaves (wi on the outer side, z > 0): pbrt-v4's
  // NormalizedFresnelBxDF, (1 - F(cos wi, ior)) / (exit_norm pi) times
  // ior^2 (radiance leaving a denser medium), cosine-sampled.
  Float exit_norm = 1.f;
};

// pbrt-v4 treats microfacet distributions with alpha below this as specular.
constexpr Float kSmoothAlpha = 1e-3f;

struct BsdfSample {
  Rgb f{0.f};        // BSDF value (for specular lobes: the delta's weight / pdf convention as in pbrt)
  Vec3 wi{0.f};      // sampled incident direction, local frame
  Float pdf = 0.f;   // solid-angle pdf (for specular lobes: the discrete lobe probability)
  uint32_t lobe = kLobeNone;  // exactly one of reflection/transmission plus one of diffuse/glossy/specular
  Float eta = 1.f;   // relative IOR crossed (1 for reflection), for Russian roulette's eta scale
};

TESSERA_HOST_DEVICE Rgb bsdf_eval(const BsdfParams& b, const Vec3& wo, const Vec3& wi);
// The value next-event estimation (light samples) multiplies: bsdf_eval but
// for the coated BSDFs, which follow pbrt-v4's light-sample estimate (layered.h).
TESSERA_HOST_DEVICE Rgb bsdf_eval_light(const BsdfParams& b, const Vec3& wo, const Vec3& wi);
TESSERA_HOST_DEVICE Float bsdf_pdf(const BsdfParams& b, const Vec3& wo, const Vec3& wi);
// uc picks among lobes, u samples within the lobe. Returns false when no
// direction could be produced (e.g. a grazing wo or a sample below the horizon).
TESSERA_HOST_DEVICE bool bsdf_sample(const BsdfParams& b, const Vec3& wo, Float uc, Vec2 u, BsdfSample* out);
// Union of the lobes this BSDF can produce.
TESSERA_HOST_DEVICE uint32_t bsdf_lobes(const BsdfParams& b);

TESSERA_HOST_DEVICE inline bool lobes_have_non_specular(uint32_t lobes) {
  return (lobes & (kLobeDiffuse | kLobeGlossy)) != 0;
}

}  // namespace tessera

#include "bsdf_impl.h"
