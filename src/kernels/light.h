// Light sources as one tagged struct. Area lights are one Light per emitting
// triangle so that light selection and pdfs stay simple.
#pragma once

#include "device.h"

namespace tessera {

enum class LightType : uint32_t { Area = 0, Point, Spot, Distant, Infinite, Goniometric, Projection };

struct Light {
  LightType type = LightType::Point;
  // Area / Distant / Infinite: emitted radiance. Point / Spot: radiant intensity.
  // pbrt's "scale" (and "power" where given) is already folded in.
  Rgb L{1.f};
  Vec3 position{0.f};          // Point / Spot
  Vec3 direction{0.f, 0.f, 1.f};  // Spot: unit cone axis. Distant: unit direction *towards* the light
  Float cos_falloff_start = 1.f;  // Spot: cos(coneangle - conedelta)
  Float cos_falloff_end = 0.f;    // Spot: cos(coneangle)
  uint32_t triangle = 0;       // Area: global triangle index in the scene
  Float area = 0.f;            // Area: triangle area (precomputed: used by every pdf)
  bool two_sided = false;      // Area
  // Infinite, Goniometric: index into the scene's images (equal-area
  // octahedral; a goniometric light's is grey); Area: an image over the
  // shape's uv that L multiplies; Projection: the slide. -1 = L alone.
  int32_t image = -1;
  Mat3 light_from_world{1.f};  // Infinite, Goniometric, Projection: into the light's frame (directions)
  // Projection: the screen window's corner (aspect, 1) or (1, 1 / aspect)
  // and tan(fov / 2); a direction w of the light's frame lands on the
  // screen at (w.x, w.y) / (w.z tan).
  Vec2 screen_max{1.f};
  Float tan_half_fov = 1.f;
  Mat3 world_from_light{1.f};  // Infinite: its inverse (set when the scene is built)
  // A blackbody emitter (pbrt-v4 "blackbody"): in spectral mode it emits
  // luminance(L) * blackbody_norm * B(lambda) / B(peak) instead of L's spectrum.
  Float blackbody_kelvin = 0.f;  // 0: L is an RGB (illuminant spectrum)
  Float blackbody_norm = 0.f;    // 1 / luminance of B / B(peak) (set when the scene is built)
  int32_t medium = -1;  // Point / Spot: the medium it sits in (pbrt-v4: the outside medium where defined)
  // Infinite with a "portal" (portal_area > 0): a rectangle p0 + a s + b t
  // (a, b in [0, 1]) in render space; the light emits only along directions
  // d with dot(d, portal_n) > 0 (pbrt-v4's PortalImageInfiniteLight), and
  // next-event estimation samples points of the rectangle.
  Vec3 portal_p0{0.f}, portal_s{0.f}, portal_t{0.f}, portal_n{0.f, 0.f, 1.f};
  Float portal_area = 0.f;
};

}  // namespace tessera
