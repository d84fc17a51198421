// Deriving the effects set of a scene (see kernels/effects.h).
#pragma once

#include <string>

#include "scene/scene_desc.h"

namespace tessera {

// Effects of the materials actually used by meshes, of the lights and textures.
uint32_t compute_effects(const SceneDesc& scene);
// "diffuse, glossy, area-lights" — stable names, in bit order.
std::string describe_effects(uint32_t effects);
std::string describe_specialisation(uint32_t spec);

}  // namespace tessera
