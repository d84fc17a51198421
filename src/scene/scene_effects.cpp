#include "scene/scene_effects.h"

#include <vector>

#include "kernels/effects.h"

namespace tessera {
namespace {

bool slot_textured(const TextureSlot& s) { return s.texture >= 0; }

void add_material_effects(const SceneDesc& scene, int32_t index, uint32_t& e, int depth) {
  if (index < 0 || index >= static_cast<int32_t>(scene.materials.size()) || depth > 16) return;
  const Material& m = scene.materials[index];
  const bool smooth = m.alpha_x < 1e-3f && m.alpha_y < 1e-3f;
  if (m.textured_roughness || m.textured_base_roughness || m.bump >= 0 || m.normal_map >= 0 ||
      slot_textured(m.layer_albedo) || slot_textured(m.layer_g))
    e |= kEffectTextures;
  switch (m.type) {
    case MaterialType::DiffuseTransmission:
      e |= kEffectDiffuse | kEffectTransmission;
      if (slot_textured(m.reflectance) || slot_textured(m.transmittance)) e |= kEffectTextures;
      break;
    case MaterialType::Diffuse:
      e |= kEffectDiffuse;
      if (slot_textured(m.reflectance)) e |= kEffectTextures;
      break;
    case MaterialType::CoatedConductor:
      e |= smooth ? kEffectSpecular : kEffectGlossy;
      if (m.base_alpha_x >= 1e-3f || m.base_alpha_y >= 1e-3f) e |= kEffectGlossy;
      if (m.conductor_from_reflectance && slot_textured(m.reflectance)) e |= kEffectTextures;
      break;
    case MaterialType::Conductor:
      e |= smooth ? kEffectSpecular : kEffectGlossy;
      if (m.conductor_from_reflectance && slot_textured(m.reflectance)) e |= kEffectTextures;
      break;
    case MaterialType::Dielectric:
      e |= (smooth ? kEffectSpecular : kEffectGlossy) | kEffectTransmission;
      break;
    case MaterialType::ThinDielectric:
      e |= kEffectSpecular | kEffectTransmission;
      break;
    case MaterialType::CoatedDiffuse:
      e |= kEffectDiffuse | (smooth ? kEffectSpecular : kEffectGlossy);
      if (slot_textured(m.reflectance)) e |= kEffectTextures;
      break;
    case MaterialType::Hair:
      e |= kEffectGlossy | kEffectTransmission;
      for (const TextureSlot* t : {&m.hair_sigma_a, &m.reflectance, &m.eumelanin, &m.pheomelanin, &m.beta_m, &m.beta_n,
                                   &m.hair_alpha})
        if (slot_textured(*t)) e |= kEffectTextures;
      break;
    case MaterialType::Subsurface:
      e |= kEffectDiffuse | kEffectTransmission | (smooth ? kEffectSpecular : kEffectGlossy);
      break;
    case MaterialType::Interface:
      e |= kEffectInterface;
      break;
    case MaterialType::Mix:
      e |= kEffectMix;
      if (slot_textured(m.amount)) e |= kEffectTextures;
      add_material_effects(scene, m.mix[0], e, depth + 1);
      add_material_effects(scene, m.mix[1], e, depth + 1);
      break;
  }
}

}  // namespace

uint32_t compute_effects(const SceneDesc& scene) {
  uint32_t e = 0;
  std::vector<bool> seen(scene.materials.size(), false);
  auto add_mesh = [&](const MeshDesc& m) {
    if (m.indices.empty()) return;
    if (m.material >= 0 && m.material < static_cast<int32_t>(seen.size()) && !seen[m.material]) {
      seen[m.material] = true;
      add_material_effects(scene, m.material, e, 0);
    }
    if (m.area_light >= 0) e |= kEffectAreaLights;
    if (!m.n.empty()) e |= kEffectShadingNormals;
    if (m.alpha.texture >= 0 || m.alpha.value.x < 1.f) e |= kEffectAlpha;
    if (m.media.inside >= 0 || m.media.outside >= 0) e |= kEffectMedia;
    if (!m.p_end.empty()) e |= kEffectMotionBlur;
  };
  for (const MeshDesc& m : scene.meshes) add_mesh(m);
  for (const ObjectDesc& o : scene.objects)
    for (const MeshDesc& m : o.meshes) add_mesh(m);
  for (const InstanceDesc& inst : scene.instances)
    if (inst.render_from_object_end != inst.render_from_object) e |= kEffectMotionBlur;
  if (scene.camera_medium >= 0) e |= kEffectMedia;
  if (scene.camera.world_from_camera_end != scene.camera.world_from_camera) e |= kEffectMotionBlur;
  for (const Light& l : scene.lights) {
    if (l.type == LightType::Infinite) e |= kEffectEnvironment;
    else if (l.type != LightType::Area) e |= kEffectDeltaLights;
  }
  return e;
}

std::string describe_effects(uint32_t e) {
  static const char* names[] = {"diffuse", "glossy", "specular", "transmission", "textures", "area-lights",
                                "delta-lights", "environment", "mix", "interface", "shading-normals", "alpha-cutouts",
                                "media", "motion-blur"};
  std::string out;
  for (uint32_t i = 0; i < sizeof(names) / sizeof(names[0]); ++i) {
    if (e & (1u << i)) {
      if (!out.empty()) out += ", ";
      out += names[i];
    }
  }
  return out.empty() ? "none" : out;
}

std::string describe_specialisation(uint32_t s) {
  if ((s & kSpecAll) == kSpecAll) return (s & kSpecNeural) ? "full+neural" : "full";
  static const char* names[] = {"non-diffuse-bsdfs", "textures", "area-lights", "environment", "guiding", "media",
                                "neural"};
  std::string out;
  for (uint32_t i = 0; i < 7; ++i) {
    if (s & (1u << i)) {
      if (!out.empty()) out += "+";
      out += names[i];
    }
  }
  if (s & kSpecNonDiffuse) return out;
  return out.empty() ? "lambertian-only" : "lambertian-only+" + out;
}

}  // namespace tessera
