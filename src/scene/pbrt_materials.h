// pbrt-v4 materials (Material, MakeNamedMaterial) as Tessera Materials.
#pragma once

#include <string>

#include "scene/pbrt_context.h"

namespace tessera {

// Builds the material of pbrt-v4 type `type`. Supported: diffuse, conductor,
// dielectric, coateddiffuse, interface, mix. Approximated with a warning:
// thindielectric and subsurface → dielectric, coatedconductor → conductor,
// diffusetransmission, measured, hair and unknown types → diffuse.
// Throws SceneError for unknown texture or material names.
Material make_material(const std::string& type, const ParamSet& params, const DirectiveContext& ctx);

// pbrt-v4's TrowbridgeReitzDistribution::RoughnessToAlpha.
Float roughness_to_alpha(Float roughness);

}  // namespace tessera
