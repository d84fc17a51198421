// Whether a scene needs spectral transport (--spectral auto): only where it
// changes the picture, since it costs more noise than RGB transport at equal
// time (docs/scene-format.md has the measurements).
#pragma once

#include <string>

#include "scene/scene_desc.h"

namespace tessera {

// Spectral transport pays on the public corpus where (a) a conductor is given
// by measured spectra (gold from .spd files: RGB is 0.7 % off pbrt-v4 in red,
// spectral within 0.1 %), (b) a dielectric disperses (a named glass or an eta
// spectrum: only spectral transport splits white light), (c) an emitter is
// strongly coloured (its weakest RGB component below half its strongest: an
// orange light through fog is 2 % off in blue in RGB, within 0.5 %
// spectrally), or (d) saturated diffuse reflectances meet over several
// bounces: RGB multiplies the reflectances' RGB, light multiplies their
// spectra, and the two products part (multibounce_colour_shift below; a
// coloured room is 2-3 % off in RGB). Returns the reason, or "" for RGB.
std::string spectral_reason(const SceneDesc& scene);

// Rule (d)'s estimate: by how much, relatively, each channel of the light that
// diffuse surfaces reflect differs between RGB and spectral transport. The
// scene is modelled as a closed room lit by white (D65) light in which every
// bounce lands on a diffuse-family surface (diffuse, coateddiffuse,
// diffusetransmission) picked at random by its share of their total area.
// Bounces are then independent, so after j of them the spectral path carries
// the j-th power of the area-weighted mean reflectance spectrum S, where RGB
// carries the j-th power of the mean reflectance RGB a:
//   shift_c = | sum_j rgb_c(D65 S^j) - sum_j a_c^j | / sum_j a_c^j,  j = 1..maxdepth,
// each spectrum being the RGB-to-spectrum upsampling the renderer itself
// uses (kernels/spectral.h). The denominator is at least 5 % of the brightest
// channel's, so that a nearly black channel does not dominate. Textured
// reflectances enter through their texels (image textures, up to 4096 texels
// evenly spread) or their constant parts (scale, mix, checkerboard of
// constants); a material with other textures (noise, marble...) is left out
// of the estimate. Other materials (glass, metal) only redirect light in this
// model and are left out too. Zero when no diffuse surface has area.
Rgb multibounce_colour_shift(const SceneDesc& scene);

// The estimated shift above which rule (d) picks spectral transport.
constexpr Float kMultibounceShiftThreshold = 0.01f;

}  // namespace tessera
