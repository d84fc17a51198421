// pbrt-v4's Sampler directive as the kernels' SamplerSetup: names, and the
// parameters each kind takes from the scene.
#pragma once

#include <string>

#include "kernels/sampler.h"
#include "scene/scene_desc.h"

namespace tessera {

// "zsobol", "paddedsobol", "sobol" (drawn as paddedsobol), "stratified",
// "independent"; throws std::invalid_argument for any other name.
SamplerKind sampler_kind_named(const std::string& name);
const char* sampler_name(SamplerKind kind);

// The setup of the scene's sampler (its seed is the scene's). ZSobol's epoch
// is the scene's sample count rounded up to a power of two; a stratified
// sampler whose strata do not multiply to the sample count (--spp overrode
// it) splits the count into the most nearly square strata, as pbrt-v4 does.
SamplerSetup sampler_setup(const SceneDesc& desc);

}  // namespace tessera
