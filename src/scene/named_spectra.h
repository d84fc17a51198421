// RGB stand-ins for pbrt-v4's spectral inputs. Tessera renders in linear sRGB,
// so every spectrum a scene names or lists is reduced to one RGB triple here.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "kernels/device.h"

namespace tessera {

// pbrt-v4's built-in named spectra ("metal-Au-eta", "glass-BK7", "stdillum-D65"...)
// as linear sRGB. Glasses give their index near 550 nm in all three channels;
// standard illuminants give (1,1,1) because pbrt-v4 normalises emission spectra
// to unit luminance. nullopt for an unknown name.
std::optional<Rgb> named_spectrum_rgb(const std::string& name);

// Blackbody emission at `kelvin`, scaled to luminance 1 (pbrt-v4 normalises
// blackbody emitters photometrically, so only the colour matters).
Rgb blackbody_rgb(Float kelvin);

// Chromaticity (CIE 1931 x, y) of a blackbody at `kelvin`.
Vec2 blackbody_xy(Float kelvin);

// A piecewise-linear spectrum given as (wavelength nm, value) pairs, reduced to
// RGB such that a constant spectrum c gives (c, c, c). A rough approximation.
Rgb sampled_spectrum_rgb(const std::vector<Float>& lambda_value_pairs);

}  // namespace tessera
