// pbrt-v4 MakeNamedMedium: "homogeneous" media (sigma_a, sigma_s, scale, g,
// Le, Lescale, and pbrt's measured "preset" names).
#pragma once

#include <optional>
#include <string>

#include "scene/pbrt_context.h"

namespace tessera {

// nullopt (with a warning) for the grid media (uniformgrid, rgbgrid, cloud,
// nanovdb), which are not simulated: shapes bounding them then enclose vacuum.
std::optional<Medium> make_medium(const std::string& type, const ParamSet& params, const DirectiveContext& ctx);

// A preset's scattering and absorption coefficients in mm^-1, as pbrt-v4's
// GetMediumScatteringProperties gives them; false for an unknown name.
bool medium_preset(const std::string& name, Rgb* sigma_a, Rgb* sigma_s);

}  // namespace tessera
