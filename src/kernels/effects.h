// The set of effects a scene uses, and the subset of it that the integrator
// is specialised on (resolved once per tile, outside the inner loop).
#pragma once

#include "device.h"

namespace tessera {

// What the scene contains (reported by the log, `tessera info` and stats).
enum Effect : uint32_t {
  kEffectDiffuse = 1u << 0,
  kEffectGlossy = 1u << 1,        // rough conductors/dielectrics, coated
  kEffectSpecular = 1u << 2,      // smooth conductors/dielectrics/coatings
  kEffectTransmission = 1u << 3,  // dielectrics
  kEffectTextures = 1u << 4,
  kEffectAreaLights = 1u << 5,
  kEffectDeltaLights = 1u << 6,   // point, spot, distant
  kEffectEnvironment = 1u << 7,   // infinite lights
  kEffectMix = 1u << 8,
  kEffectInterface = 1u << 9,
  kEffectShadingNormals = 1u << 10,
  kEffectAlpha = 1u << 11,        // alpha cutouts (a ray-query filter, only where present)
  kEffectMedia = 1u << 12,        // participating media (volumetric path tracing)
  kEffectMotionBlur = 1u << 13,   // moving shapes (a time per camera ray)
};

// What the integrator template is specialised on: each bit removes work from
// the inner loop when clear.
enum Specialisation : uint32_t {
  kSpecNonDiffuse = 1u << 0,   // any BSDF other than Lambertian (incl. mix/interface)
  kSpecTextures = 1u << 1,
  kSpecAreaLights = 1u << 2,
  kSpecEnvironment = 1u << 3,
  kSpecGuiding = 1u << 4,      // learned guiding (set by the render options, not by the scene)
  kSpecSurfaceAll = (1u << 5) - 1,
  // Volumetric path tracing: media, and shadow rays that pass "interface"
  // surfaces (pbrt-v4's volpath). Such scenes are rare enough that they get
  // the full surface integrator (every other scene bit set) rather than a
  // specialisation per combination: two more instantiations, not 32.
  kSpecMedia = 1u << 5,
  kSpecAll = (1u << 6) - 1,
  // The neural guide instead of the Q-table (with kSpecGuiding). Like media,
  // it runs the full surface integrator, except in scenes of Lambertian
  // surfaces and area lights alone: three instantiations (one with media;
  // render/render_tile_impl.h).
  kSpecNeural = 1u << 6,
  kSpecIndexCount = 1u << 7,  // every combination of the bits above
};

// Scenes of Lambertian surfaces and area lights alone (no textures, no
// environment, no media), whatever the guiding bit: the neural guide runs
// an instantiation of its own there (render/render_tile_impl.h).
TESSERA_HOST_DEVICE constexpr bool lambertian_area_lights_only(uint32_t spec) {
  return (spec & (kSpecMedia | (kSpecSurfaceAll & ~kSpecGuiding))) == kSpecAreaLights;
}

TESSERA_HOST_DEVICE inline uint32_t specialisation_for(uint32_t effects) {
  uint32_t s = 0;
  if (effects & (kEffectGlossy | kEffectSpecular | kEffectTransmission | kEffectMix | kEffectInterface)) s |= kSpecNonDiffuse;
  if (effects & kEffectTextures) s |= kSpecTextures;
  if (effects & kEffectAreaLights) s |= kSpecAreaLights;
  if (effects & kEffectEnvironment) s |= kSpecEnvironment;
  if (effects & (kEffectMedia | kEffectInterface))
    s |= kSpecMedia | kSpecNonDiffuse | kSpecTextures | kSpecAreaLights | kSpecEnvironment;
  return s;
}

}  // namespace tessera
