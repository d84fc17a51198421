// pbrt-v4 MakeNamedMedium: "homogeneous" media (sigma_a, sigma_s, scale, g,
// Le, Lescale, and pbrt's measured "preset" names) and the grid media
// "uniformgrid", "rgbgrid", "nanovdb" and "cloud".
#pragma once

#include <string>

#include "scene/pbrt_context.h"

namespace tessera {

// A grid medium's lattices are added to ctx.scene.grids, its box placed by
// world_from_medium (the CTM). Unknown types and bad values are errors.
Medium make_medium(const std::string& type, const ParamSet& params, const Mat4& world_from_medium,
                                  const DirectiveContext& ctx);

// A preset's scattering and absorption coefficients in mm^-1, as pbrt-v4's
// GetMediumScatteringProperties gives them; false for an unknown name.
bool medium_preset(const std::string& name, Rgb* sigma_a, Rgb* sigma_s);

// A scattering or absorption coefficient: finite and not negative in every channel.
bool valid_coefficient(const Rgb& c);

}  // namespace tessera
