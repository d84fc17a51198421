#include "scene/pbrt_materials.h"

#include <algorithm>
#include <cmath>
#include <functional>

#include "kernels/bsdf.h"
#include "scene/named_spectra.h"
#include "scene/pbrt_media.h"
#include "scene/subsurface_params.h"
#include "scene/pbrt_textures.h"

namespace tessera {
namespace {

// roughness / uroughness / vroughness / remaproughness, shared by the
// microfacet materials. `prefix` selects e.g. "conductor." for coatedconductor.
void read_roughness(Material& m, const ParamSet& params, const DirectiveContext& ctx, const std::string& prefix = "") {
  const TextureSlot r = float_slot(params, prefix + "roughness", 0.f, ctx);
  const TextureSlot u = params.find_any(prefix + "uroughness") ? float_slot(params, prefix + "uroughness", 0.f, ctx) : r;
  const TextureSlot v = params.find_any(prefix + "vroughness") ? float_slot(params, prefix + "vroughness", 0.f, ctx) : r;
  m.remap_roughness = params.get_bool("remaproughness", true);
  auto constant = [&](const TextureSlot& s, Float* out) {
    if (s.texture >= 0 && ctx.scene.textures[s.texture].type != TextureType::Constant) return false;
    *out = s.texture < 0 ? s.value.x : ctx.scene.textures[s.texture].value.x;
    return true;
  };
  Float cu = 0.f, cv = 0.f;
  if (constant(u, &cu) && constant(v, &cv)) {
    m.alpha_x = m.remap_roughness ? roughness_to_alpha(cu) : cu;
    m.alpha_y = m.remap_roughness ? roughness_to_alpha(cv) : cv;
    return;
  }
  // Evaluated at every hit (textured materials pay for it, others do not).
  m.textured_roughness = true;
  m.roughness_u = u;
  m.roughness_v = v;
  m.alpha_x = m.alpha_y = 1.f;  // not smooth: the effects set counts it as glossy
}

// Appends a sampled spectrum (kSpectralSamples values) to the scene's pool;
// returns its index there.
int32_t add_spectrum(SceneDesc& scene, const std::vector<Float>& samples) {
  const auto index = static_cast<int32_t>(scene.spectra.size() / kSpectralSamples);
  scene.spectra.insert(scene.spectra.end(), samples.begin(), samples.end());
  return index;
}

// A dielectric index of refraction: a float, or a spectrum (named glasses,
// samples) read at 550 nm (green channel) for RGB transport. A spectrum
// that varies is also kept (Material::ior_spectrum) for dispersion in
// spectral transport, when `m` is given.
Float read_ior(const ParamSet& params, const std::string& name, Float fallback, const DirectiveContext& ctx,
               Material* m = nullptr) {
  if (params.get_texture(name)) {
    ctx.warn("a texture for '" + name + "' is not supported; using " + std::to_string(fallback));
    return fallback;
  }
  const std::optional<Rgb> rgb = params.get_rgb(name, /*allow_float=*/true);
  if (!rgb) return fallback;
  const Param* p = params.find_any(name);
  if (m && p && p->type == "spectrum") {
    std::optional<std::vector<Float>> samples;
    if (!p->strings.empty()) samples = named_spectrum_samples(p->strings[0]);
    else samples = resample_spectrum(std::vector<Float>(p->numbers.begin(), p->numbers.end()));
    const bool varies = samples && std::adjacent_find(samples->begin(), samples->end(), std::not_equal_to<>()) !=
                                       samples->end();
    if (varies) m->ior_spectrum = add_spectrum(ctx.scene, *samples);
  }
  return rgb->y;
}

Rgb read_constant_rgb(const ParamSet& params, const std::string& name, Rgb fallback, const DirectiveContext& ctx) {
  TextureSlot s = spectrum_slot(params, name, fallback, ctx);
  if (s.texture < 0) return s.value;
  const Texture& t = ctx.scene.textures[s.texture];
  if (t.type == TextureType::Constant) return t.value;
  ctx.warn("a non-constant texture for '" + name + "' is not supported; using its default");
  return fallback;
}

void read_conductor(Material& m, const ParamSet& params, const DirectiveContext& ctx, const std::string& prefix) {
  m.type = MaterialType::Conductor;
  if (params.find_any(prefix + "reflectance")) {
    m.conductor_from_reflectance = true;
    m.reflectance = spectrum_slot(params, prefix + "reflectance", Rgb(1.f), ctx);
  } else if (const Param* e = params.find_any(prefix + "eta"), *kp = params.find_any(prefix + "k");
             e && kp && e->type == "spectrum" && kp->type == "spectrum" && e->strings.empty() && kp->strings.empty()) {
    // Both measured spectra (.spd files or inline samples): kept for spectral
    // transport, and fitted together for RGB (named_spectra.h).
    std::vector<Float> eta_pairs(e->numbers.begin(), e->numbers.end()), k_pairs(kp->numbers.begin(), kp->numbers.end());
    // Under a coat the conductor is seen from the coat's index (pbrt-v4 divides eta and k by it).
    const Float outside = prefix == "conductor." ? read_ior(params, "interface.eta", 1.5f, ctx) : 1.f;
    sampled_conductor_rgb(eta_pairs, k_pairs, outside, &m.eta, &m.k);
    e->used = kp->used = true;
    m.eta_spectrum = add_spectrum(ctx.scene, resample_spectrum(eta_pairs));
    m.k_spectrum = add_spectrum(ctx.scene, resample_spectrum(k_pairs));
    const std::string files =
        e->file.empty() || kp->file.empty() ? std::string() : " (files '" + e->file + "', '" + kp->file + "')";
    ctx.warn("conductor \"" + prefix + "eta\" and \"" + prefix + "k\" spectra" + files +
             " used as spectra with --spectral on; reduced to RGB (matching their normal-incidence reflectance) otherwise");
  } else {
    // A lone "float eta" is allowed too (grey).
    const Material defaults;
    m.eta = read_constant_rgb(params, prefix + "eta", defaults.eta, ctx);
    if (auto f = params.get_float(prefix + "eta", -1.f); f > 0.f) m.eta = Rgb(f);
    m.k = read_constant_rgb(params, prefix + "k", defaults.k, ctx);
    if (auto f = params.get_float(prefix + "k", -1.f); f >= 0.f) m.k = Rgb(f);
  }
  read_roughness(m, params, ctx, prefix);
}

// The layer of the coated materials: thickness, the random walk's depth and
// sample count, and its scattering medium ("albedo", "g").
void read_layer(Material& m, const ParamSet& params, const DirectiveContext& ctx, const std::string& type) {
  m.thickness = constant_float(params, "thickness", 0.01f, ctx);
  const int max_depth = params.get_int("maxdepth", 10), samples = params.get_int("nsamples", 1);
  if (!(m.thickness >= 0.f)) ctx.fail(type + " \"thickness\" must not be negative");
  if (max_depth < 1 || max_depth > 1000) ctx.fail(type + " \"maxdepth\" must be in 1..1000");
  if (samples < 1 || samples > 1000) ctx.fail(type + " \"nsamples\" must be in 1..1000");
  m.layer_max_depth = static_cast<uint32_t>(max_depth);
  m.layer_samples = static_cast<uint32_t>(samples);
  m.layer_albedo = spectrum_slot(params, "albedo", Rgb(0.f), ctx);
  m.layer_g = float_slot(params, "g", 0.f, ctx);
}

// pbrt-v4's HairMaterial: absorption from "sigma_a", else "reflectance"
// (pbrt-v3's "color" too), else the melanins (eumelanin 1.3 when none is given).
void read_hair(Material& m, const ParamSet& params, const DirectiveContext& ctx) {
  m.type = MaterialType::Hair;
  const char* colour = params.find_any("reflectance") ? "reflectance" : "color";
  const bool sigma_a = params.find_any("sigma_a") != nullptr, reflectance = params.find_any(colour) != nullptr;
  const bool melanin = params.find_any("eumelanin") || params.find_any("pheomelanin");
  if (sigma_a) {
    m.hair_absorption = HairAbsorption::SigmaA;
    m.hair_sigma_a = spectrum_slot(params, "sigma_a", Rgb(0.f), ctx);
    if (reflectance) ctx.warn(std::string("hair \"") + colour + "\" is ignored: \"sigma_a\" is given");
    if (melanin) ctx.warn("hair melanin concentrations are ignored: \"sigma_a\" is given");
  } else if (reflectance) {
    m.hair_absorption = HairAbsorption::Reflectance;
    m.reflectance = spectrum_slot(params, colour, Rgb(0.5f), ctx);
    if (melanin) ctx.warn(std::string("hair melanin concentrations are ignored: \"") + colour + "\" is given");
  } else {
    m.hair_absorption = HairAbsorption::Melanin;
    // pbrt-v4: eumelanin 1.3 only when no absorption is given at all.
    m.eumelanin = float_slot(params, "eumelanin", melanin ? 0.f : 1.3f, ctx);
    m.pheomelanin = float_slot(params, "pheomelanin", 0.f, ctx);
  }
  m.ior = read_ior(params, "eta", 1.55f, ctx);
  if (!(m.ior > 0.f) || !std::isfinite(m.ior)) ctx.fail("hair \"eta\" must be positive");
  m.beta_m = float_slot(params, "beta_m", 0.3f, ctx);
  m.beta_n = float_slot(params, "beta_n", 0.3f, ctx);
  m.hair_alpha = float_slot(params, "alpha", 2.f, ctx);
}

// pbrt-v4's "subsurface" as a random walk (docs/scene-format.md): a
// dielectric boundary (eta 1.33, roughness) around a homogeneous medium
// whose coefficients follow pbrt-v4's precedence: a named measured medium
// ("name"), else "sigma_a" and "sigma_s", else "reflectance" with "mfp"
// (inverted to an albedo by Chiang et al. 2016's fit for random walks, where
// pbrt-v4 inverts its photon-beam-diffusion table), else pbrt-v4's default
// (whole milk's); each times "scale". The medium is added to the scene; the
// parser puts it inside every shape with this material.
void read_subsurface(Material& m, const ParamSet& params, const DirectiveContext& ctx) {
  m.type = MaterialType::Subsurface;
  m.ior = read_ior(params, "eta", 1.33f, ctx);
  read_roughness(m, params, ctx);
  if (!(m.ior > 0.f) || !std::isfinite(m.ior)) ctx.fail("subsurface \"eta\" must be positive");
  const Float scale = params.get_float("scale", 1.f);
  if (!(scale >= 0.f) || !std::isfinite(scale)) ctx.fail("subsurface \"scale\" must be finite and not negative");
  Rgb sigma_a(0.0011f, 0.0024f, 0.014f), sigma_s(2.55f, 3.21f, 3.77f);
  // A float or rgb constant, or a constant texture.
  auto constant = [&](const char* name, Rgb fallback) {
    if (const std::optional<Rgb> v = params.get_rgb(name, /*allow_float=*/true)) return *v;
    return read_constant_rgb(params, name, fallback, ctx);
  };
  const std::string name = params.get_string("name", "");
  const bool has_a = params.find_any("sigma_a") != nullptr, has_s = params.find_any("sigma_s") != nullptr;
  if (!name.empty()) {
    if (!medium_preset(name, &sigma_a, &sigma_s)) ctx.fail("subsurface \"name\" \"" + name + "\" is not a known medium");
    sigma_a *= scale;
    sigma_s *= scale;
  } else if (has_a || has_s) {
    if (!(has_a && has_s)) ctx.fail("subsurface needs both \"sigma_a\" and \"sigma_s\"");
    sigma_a = scale * constant("sigma_a", sigma_a);
    sigma_s = scale * constant("sigma_s", sigma_s);
  } else if (params.find_any("reflectance")) {
    // pbrt-v4: the mean free path is scale x mfp.
    const Rgb r = glm::clamp(constant("reflectance", Rgb(0.5f)), Rgb(0.f), Rgb(1.f));
    const Rgb mfp = scale * constant("mfp", Rgb(1.f));
    for (int c = 0; c < 3; ++c) {
      if (!(mfp[c] > 0.f) || !std::isfinite(1.f / mfp[c])) ctx.fail("subsurface \"mfp\" times \"scale\" must be positive");
      const Float albedo = random_walk_albedo(r[c]);
      sigma_s[c] = albedo / mfp[c];
      sigma_a[c] = (1.f - albedo) / mfp[c];
    }
  } else {
    sigma_a *= scale;
    sigma_s *= scale;
  }
  if (!valid_coefficient(sigma_a) || !valid_coefficient(sigma_s))
    ctx.fail("subsurface coefficients must be finite and not negative");
  Medium medium;
  medium.sigma_a = sigma_a;
  medium.sigma_s = sigma_s;
  medium.subsurface = 1;
  medium.g = std::clamp(params.get_float("g", 0.f), -0.99f, 0.99f);
  if (!std::isfinite(medium.g)) ctx.fail("subsurface \"g\" must be finite");
  if (ctx.scene.media.size() >= static_cast<size_t>(INT16_MAX)) ctx.fail("too many media (at most 32767)");
  ctx.scene.media.push_back(medium);
  m.subsurface_medium = static_cast<int32_t>(ctx.scene.media.size() - 1);
  m.exit_norm = normalized_fresnel_norm(m.ior);
}

}  // namespace

Float roughness_to_alpha(Float roughness) { return std::sqrt(std::max(roughness, 0.f)); }

Material make_material(const std::string& type, const ParamSet& params, const DirectiveContext& ctx) {
  Material m;
  if (type == "diffuse") {
    m.type = MaterialType::Diffuse;
    m.reflectance = spectrum_slot(params, "reflectance", Rgb(0.5f), ctx);
  } else if (type == "conductor") {
    read_conductor(m, params, ctx, "");
  } else if (type == "dielectric") {
    m.type = MaterialType::Dielectric;
    m.ior = read_ior(params, "eta", 1.5f, ctx, &m);
    read_roughness(m, params, ctx);
  } else if (type == "thindielectric") {
    m.type = MaterialType::ThinDielectric;  // pbrt-v4: smooth only
    m.ior = read_ior(params, "eta", 1.5f, ctx, &m);
  } else if (type == "coateddiffuse") {
    m.type = MaterialType::CoatedDiffuse;
    m.reflectance = spectrum_slot(params, "reflectance", Rgb(0.5f), ctx);
    m.ior = read_ior(params, "eta", 1.5f, ctx, &m);
    read_roughness(m, params, ctx);
    read_layer(m, params, ctx, type);
  } else if (type == "coatedconductor") {
    // The conductor first (its roughness becomes the base's), then the coat.
    read_conductor(m, params, ctx, "conductor.");
    if (m.conductor_from_reflectance == false && params.find_any("reflectance")) {
      m.conductor_from_reflectance = true;
      m.reflectance = spectrum_slot(params, "reflectance", Rgb(1.f), ctx);
    }
    if (m.textured_roughness) {  // the interface's roughness goes in roughness_u/v
      m.textured_base_roughness = true;
      m.base_roughness_u = m.roughness_u;
      m.base_roughness_v = m.roughness_v;
      m.textured_roughness = false;
    }
    m.type = MaterialType::CoatedConductor;
    m.base_alpha_x = m.alpha_x;
    m.base_alpha_y = m.alpha_y;
    m.ior = read_ior(params, "interface.eta", 1.5f, ctx, &m);
    read_roughness(m, params, ctx, "interface.");
    read_layer(m, params, ctx, type);
    const bool smooth = std::max(m.alpha_x, m.alpha_y) < kSmoothAlpha && std::max(m.base_alpha_x, m.base_alpha_y) < kSmoothAlpha;
    if (smooth && (m.layer_albedo.texture >= 0 || !is_black(m.layer_albedo.value)))
      ctx.warn("coatedconductor \"albedo\" between a smooth coat and a smooth conductor is not simulated; the layer "
               "only absorbs by its thickness");
  } else if (type == "interface" || type == "none" || type == "") {
    m.type = MaterialType::Interface;
  } else if (type == "mix") {
    m.type = MaterialType::Mix;
    std::vector<std::string> names = params.get_strings("materials");
    if (names.size() != 2) ctx.fail("mix material needs two names in \"string materials\"");
    for (int i = 0; i < 2; ++i) {
      auto it = ctx.names.materials.find(names[i]);
      if (it == ctx.names.materials.end()) ctx.fail("unknown named material \"" + names[i] + "\" in mix");
      m.mix[i] = it->second;
    }
    // Mixes of mixes resolve in a bounded loop: deeper nesting is an error
    // here, not a silent default material at render time. The parser adds
    // this material next, at index materials.size().
    int32_t depth = 1;
    for (int32_t component : m.mix) {
      auto d = ctx.names.mix_depth.find(component);
      if (d != ctx.names.mix_depth.end()) depth = std::max(depth, d->second + 1);
    }
    if (depth > kMaxMixNesting)
      ctx.fail("mix material nests " + std::to_string(depth) + " mixes deep; at most " +
               std::to_string(kMaxMixNesting) + " are supported");
    ctx.names.mix_depth[static_cast<int32_t>(ctx.scene.materials.size())] = depth;
    m.amount = float_slot(params, "amount", 0.5f, ctx);
  } else if (type == "subsurface") {
    read_subsurface(m, params, ctx);
  } else if (type == "hair") {
    read_hair(m, params, ctx);
  } else if (type == "diffusetransmission") {
    m.type = MaterialType::DiffuseTransmission;
    m.reflectance = spectrum_slot(params, "reflectance", Rgb(0.25f), ctx);
    m.transmittance = spectrum_slot(params, "transmittance", Rgb(0.25f), ctx);
    m.scale = params.get_float("scale", 1.f);
    if (!(m.scale >= 0.f)) ctx.fail("diffusetransmission \"scale\" must not be negative");
  } else {
    ctx.warn("material \"" + type + "\" is not supported; using diffuse 0.5");
    params.mark_all_used();
  }
  // pbrt-v4's bump mapping: a float texture of displacement along the normal.
  if (params.find_any("displacement")) {
    const TextureSlot bump = float_slot(params, "displacement", 0.f, ctx);
    if (bump.texture >= 0) m.bump = bump.texture;
    else if (bump.value.x != 0.f) ctx.warn("a constant material \"displacement\" does not bump; ignored");
  }
  const std::string normal_map = params.get_string("normalmap", "");
  if (!normal_map.empty()) m.normal_map = image_index(normal_map, "linear", false, ctx);
  return m;
}

}  // namespace tessera
