// pbrt-v4 "Texture" directives and the texture-or-constant parameter slots
// that materials use.
#pragma once

#include <optional>
#include <string>

#include "scene/pbrt_context.h"

namespace tessera {

// Texture "name" "float"|"spectrum" "class" ...: appends to scene.textures and
// registers the name. render_from_texture: the CTM at the directive. Unsupported
// classes (ptex) warn and become a constant 0.5.
void make_named_texture(const std::string& name, const std::string& kind, const std::string& texture_class,
                        const ParamSet& params, const glm::dmat4& render_from_texture, const DirectiveContext& ctx);

// A spectrum parameter: "texture name" → named texture (unknown → SceneError),
// else rgb/spectrum/blackbody constant, else `fallback`.
TextureSlot spectrum_slot(const ParamSet& params, const std::string& name, Rgb fallback, const DirectiveContext& ctx);
// A float parameter: "texture name" → named float texture, else "float name".
TextureSlot float_slot(const ParamSet& params, const std::string& name, Float fallback, const DirectiveContext& ctx);
// A float parameter that must be constant (roughness, eta): a constant
// texture's value is used; any other texture warns and gives `fallback`.
Float constant_float(const ParamSet& params, const std::string& name, Float fallback, const DirectiveContext& ctx);

// Loads (once per path and encoding) an image into scene.images; returns its
// index. Throws SceneError naming the file when it is missing or unreadable.
int32_t image_index(const std::string& filename, const std::string& encoding, bool grey, const DirectiveContext& ctx);

}  // namespace tessera
