// pbrt-v4's Sampler directive as the kernels' SamplerSetup: names, and the
// parameters each kind takes from the scene.
#pragma once

#include <optional>
#include <string>

#include "kernels/sampler.h"
#include "scene/scene_desc.h"

namespace tessera {

// "zsobol", "paddedsobol", "sobol" (drawn as paddedsobol), "stratified",
// "independent", "halton"; nothing for any other name.
std::optional<SamplerKind> sampler_kind_named(const std::string& name);
const char* sampler_name(SamplerKind kind);

// The setup of the scene's sampler (its seed is the scene's). ZSobol's epoch
// is the scene's own sample count rounded up to a power of two, and the
// strata are the scene's: --spp changes neither (pbrt-v4 re-splits its
// strata for --spp), so that a checkpoint resumes with any --spp; samples
// past one epoch or round start the next. Halton's pixel layout follows the
// film's resolution, as pbrt-v4's does.
SamplerSetup sampler_setup(const SceneDesc& desc);

}  // namespace tessera
