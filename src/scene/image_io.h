// Reading texture and environment images into linear RGB.
#pragma once

#include <array>
#include <optional>
#include <string>

#include "scene/scene_desc.h"

namespace tessera {

// How 8/16-bit texel values map to linear (pbrt-v4 imagemap "encoding").
// Float images (EXR, HDR) are always linear.
struct ColorEncoding {
  enum Kind { SRGB, Linear, Gamma } kind = SRGB;
  Float gamma = 2.2f;  // Gamma only
  std::string name() const;
};

// "sRGB", "linear", "gamma 2.2"; nullopt if not one of those.
std::optional<ColorEncoding> parse_color_encoding(const std::string& text);

// EXR (OpenEXR), or PNG/TGA/JPEG/BMP/PFM/HDR and the rest OpenImageIO reads. Row 0 is the top of the
// file. Throws SceneError("cannot read image '<path>': <reason>").
ImageDesc load_image(const std::string& path);  // 8-bit data treated as sRGB

// Three channels of an EXR as 32-bit floats (e.g. {"R","G","B"} or a
// layer such as {"variance.R","variance.G","variance.B"}); nullopt when
// the file lacks one of them. Throws SceneError like load_image.
std::optional<ImageDesc> load_exr_layer(const std::string& path, const std::array<const char*, 3>& channels);
ImageDesc load_image(const std::string& path, const ColorEncoding& encoding);

}  // namespace tessera
