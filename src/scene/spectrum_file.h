// pbrt-v4's spectrum files (".spd"): wavelength/value pairs as plain numbers,
// '#' starting a comment that runs to the end of the line.
#pragma once

#include <string>
#include <vector>

#include "kernels/device.h"

namespace tessera {

// The pairs of `path` as (lambda nm, value, lambda nm, value, ...), checked
// as pbrt-v4 checks them: an even count, at least one pair, wavelengths
// strictly increasing, every number finite. Throws
// SceneError("cannot read spectrum file '<path>': <reason>").
std::vector<Float> read_spectrum_file(const std::string& path);

// The same from text already in memory; `name` is used in messages only.
std::vector<Float> parse_spectrum_text(const std::string& text, const std::string& name);

}  // namespace tessera
