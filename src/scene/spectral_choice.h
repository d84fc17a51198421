// Whether a scene needs spectral transport (--spectral auto): only where it
// changes the picture, since it costs about twice the noise of RGB transport
// at equal time (docs/scene-format.md has the measurements).
#pragma once

#include <string>

#include "scene/scene_desc.h"

namespace tessera {

// Spectral transport pays on the public corpus where (a) a conductor is given
// by measured spectra (gold from .spd files: RGB is 0.7 % off pbrt-v4 in red,
// spectral within 0.1 %), (b) a dielectric disperses (a named glass or an eta
// spectrum: only spectral transport splits white light), or (c) an emitter is strongly coloured (its weakest
// RGB component below half its strongest: an orange light through fog is
// 2 % off in blue in RGB, within 0.5 % spectrally). White light on coloured
// surfaces matches pbrt-v4 within 0.3 % in RGB. Returns the reason, or "" for RGB.
std::string spectral_reason(const SceneDesc& scene);

}  // namespace tessera
