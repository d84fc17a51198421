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
// diffuse surfaces reflect differs between RGB and spectral transport, under
// white (D65) light. Light first bounces off a diffuse-family surface
// (diffuse, coateddiffuse, diffusetransmission) picked by its share of their
// area, then lands where light leaving such a surface lands: measured by 1024
// rays from 128 points spread by area, cosine-distributed on the side that
// sees more of the scene, against the scene's triangles (a ray that leaves
// the scene lands nowhere; one that lands on glass or metal carries on
// uncoloured; instanced geometry is not tested). With F the mean first-bounce
// reflectance spectrum and N the landing-weighted one (RGB: f and n),
//   shift_c = | sum_j rgb_c(D65 F N^(j-1)) - sum_j f_c n_c^(j-1) | / sum_j f_c n_c^(j-1),  j = 1..maxdepth,
// each spectrum the RGB-to-spectrum upsampling the renderer itself uses
// (kernels/spectral.h). The denominator is at least 5 % of the brightest
// channel's, so that a nearly black channel does not dominate. Textured
// reflectances enter through their texels (image textures: up to 4096
// texels, evenly spread) or their constant parts (scale, mix, checkerboard,
// dots, bilerp); a material with a noise texture (fbm, wrinkled, windy,
// marble) is left out, as its colours are unknown without evaluating it.
// Deterministic (a fixed seed); the rays cost about 0.05 s on 80,000
// triangles. Zero when no diffuse surface has area. It overestimates: the
// camera sees some surfaces more than their area says and light does not
// reach every surface equally: tests/data/coloured-room.pbrt, estimated 1.7 %,
// is 1.0 % off pbrt-v4 in RGB).
Rgb multibounce_colour_shift(const SceneDesc& scene);

// The estimated shift above which rule (d) picks spectral transport.
constexpr Float kMultibounceShiftThreshold = 0.01f;

}  // namespace tessera
