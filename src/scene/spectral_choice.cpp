#include "scene/spectral_choice.h"

#include <algorithm>

#include "kernels/vecmath.h"
#include "scene/named_spectra.h"

namespace tessera {
namespace {

bool strongly_coloured(Rgb c) {
  const Float hi = max_component(c), lo = std::min({c.x, c.y, c.z});
  return hi > 0.f && lo < 0.5f * hi;
}

}  // namespace

std::string spectral_reason(const SceneDesc& scene) {
  for (const Material& m : scene.materials) {
    if (m.ior_spectrum >= 0) return "a dispersive dielectric";
    if (m.eta_spectrum >= 0 || m.k_spectrum >= 0) return "a conductor given by measured spectra";
  }
  for (const AreaLightDesc& a : scene.area_lights) {
    if (a.image >= 0) continue;  // an image's texels: natural colours
    const Rgb c = a.blackbody_kelvin > 0.f ? blackbody_rgb(a.blackbody_kelvin) : a.L;
    if (strongly_coloured(c)) return "a strongly coloured area light";
  }
  for (const Light& l : scene.lights) {
    if (l.type == LightType::Infinite && l.image >= 0) continue;  // an image's texels: natural colours
    const Rgb c = l.blackbody_kelvin > 0.f ? blackbody_rgb(l.blackbody_kelvin) : l.L;
    if (strongly_coloured(c)) return "a strongly coloured light";
  }
  for (const Medium& m : scene.media) {
    if (strongly_coloured(m.Le)) return "a strongly coloured emitting medium";
    // Blackbodies below about 5000 K are strongly coloured; fire is far below.
    if (m.grid >= 0 && scene.grids[static_cast<size_t>(m.grid)].temperature.nx > 0) return "a medium glowing by temperature";
  }
  return "";
}

}  // namespace tessera
