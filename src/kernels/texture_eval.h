// Evaluating textures at a surface point (point sampling; no ray differentials yet).
#pragma once

#include "image_sampling.h"
#include "procedural_texture.h"
#include "scene_view.h"
#include "surface.h"
#include "texture_mapping.h"
#include "vecmath.h"

namespace tessera {

// Whether the integer cell holding x is odd, from floor(x) in float (no cast
// to overflow; NaN and cells beyond float's integers read even), so that a
// checkerboard's parity is the XOR of its axes' (a sum of cell indices would
// round at 2^24).
TESSERA_HOST_DEVICE inline bool odd_cell(Float x) {
  const Float half = glm::floor(x) * 0.5f;
  return half != glm::floor(half);
}

// Textures may nest (scale of a checkerboard of images...). The recursion
// terminates because the loader only lets a texture reference earlier ones.
TESSERA_HOST_DEVICE TESSERA_DEVICE_NOINLINE inline Rgb eval_texture(const SceneView& s, int32_t tex_index, const TexturePoint& tp) {
  const Texture& t = s.textures[tex_index];
  auto slot = [&](const TextureSlot& v) { return v.texture >= 0 ? eval_texture(s, v.texture, tp) : v.value; };
  switch (t.type) {
    case TextureType::Constant:
      return t.value;
    case TextureType::Image: {
      Rgb v = image_lookup(s.images[t.image], texture_st(t, tp), t.wrap, t.filter) * t.scale;
      return t.invert ? glm::max(Rgb(0.f), Rgb(1.f) - v) : v;
    }
    case TextureType::Scale: {  // pbrt-v4: a zero scale does not evaluate the texture
      const Rgb b = slot(t.b);
      return b == Rgb(0.f) ? b : slot(t.a) * b;
    }
    case TextureType::Checkerboard: {
      // pbrt-v4's checkerboard, point sampled: tex2 where the cells' parities differ.
      bool odd;
      if (t.mapping == TextureMapping::Point3D) {
        const Vec3 q = texture_space_point(t, tp.p);
        odd = (odd_cell(q.x) != odd_cell(q.y)) != odd_cell(q.z);
      } else {
        const Vec2 st = texture_st(t, tp);
        odd = odd_cell(st.x) != odd_cell(st.y);
      }
      return slot(odd ? t.b : t.a);
    }
    case TextureType::Mix: {  // pbrt-v4 MixTexture: a component with weight 0 is not evaluated
      const Float amt = slot(t.amount).x;
      Rgb v(0.f);
      if (amt != 1.f) v += (1.f - amt) * slot(t.a);
      if (amt != 0.f) v += amt * slot(t.b);
      return v;
    }
    case TextureType::DirectionMix: {  // pbrt-v4: |n . dir| of tex1, the rest tex2
      const Float amt = glm::abs(glm::dot(tp.n, t.dir));
      Rgb v(0.f);
      if (amt != 0.f) v += amt * slot(t.a);
      if (amt != 1.f) v += (1.f - amt) * slot(t.b);
      return v;
    }
    case TextureType::Bilerp: {  // corners v00, v01, v10, v11 at (s, t) = (0,0), (0,1), (1,0), (1,1)
      const Vec2 st = texture_st(t, tp);
      return (1.f - st.x) * (1.f - st.y) * t.corners[0] + (1.f - st.x) * st.y * t.corners[1] +
             st.x * (1.f - st.y) * t.corners[2] + st.x * st.y * t.corners[3];
    }
    case TextureType::Dots:
      return slot(inside_polka_dot(texture_st(t, tp)) ? t.a : t.b);
    case TextureType::FBm:
      return Rgb(fbm_noise(texture_space_point(t, tp.p), t.omega, t.octaves));
    case TextureType::Wrinkled:
      return Rgb(turbulence_noise(texture_space_point(t, tp.p), t.omega, t.octaves));
    case TextureType::Windy:
      return Rgb(windy_value(texture_space_point(t, tp.p)));
    case TextureType::Marble:
      return marble_value(t.scale * texture_space_point(t, tp.p), t.variation, t.omega, t.octaves);
  }
  return Rgb(0.f);
}

TESSERA_HOST_DEVICE inline Rgb eval_slot(const SceneView& s, const TextureSlot& slot, const TexturePoint& tp) {
  return slot.texture >= 0 ? eval_texture(s, slot.texture, tp) : slot.value;
}

TESSERA_HOST_DEVICE inline TexturePoint texture_point(const SurfaceHit& h) { return TexturePoint{h.p, h.ng, h.uv}; }

}  // namespace tessera
