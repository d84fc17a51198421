// pbrt-v4 LightSource and AreaLightSource directives.
#pragma once

#include <optional>
#include <string>

#include "scene/pbrt_context.h"

namespace tessera {

// point, spot, goniometric, projection, distant, infinite (constant "L" or
// equal-area "filename"). Unknown types: a warning and nullopt. `world_from_light`
// is the CTM. Light "scale" (and "power"/"illuminance", as pbrt-v4 applies
// them) are folded into L. `render_from_world` places an infinite light's
// "portal", whose points pbrt-v4 reads in world space, not the light's.
std::optional<Light> make_light(const std::string& type, const ParamSet& params, const Mat4& world_from_light,
                                const Mat4& render_from_world,
                                const DirectiveContext& ctx);

// AreaLightSource "diffuse" ("L" or an image "filename", "scale", "twosided",
// "power"). Other types warn and still give a diffuse emitter.
AreaLightDesc make_area_light(const std::string& type, const ParamSet& params, const DirectiveContext& ctx);

}  // namespace tessera
