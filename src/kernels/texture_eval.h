// Evaluating textures at a surface point (point sampling; no ray differentials yet).
#pragma once

#include "scene_view.h"
#include "vecmath.h"

namespace tessera {

TESSERA_HOST_DEVICE inline Rgb image_bilerp(const ImageView& img, Vec2 st) {
  // pbrt-v4 flips t for image lookups and wraps with "repeat". Wrapping in
  // float first keeps the integer conversions in range for any st (NaN -> 0).
  st = st - glm::floor(st);
  if (!(st.x >= 0.f && st.x <= 1.f)) st.x = 0.f;
  if (!(st.y >= 0.f && st.y <= 1.f)) st.y = 0.f;
  Float x = st.x * img.width - 0.5f, y = (1.f - st.y) * img.height - 0.5f;
  Float fx = glm::floor(x), fy = glm::floor(y);
  Float dx = x - fx, dy = y - fy;
  auto texel = [&](int32_t ix, int32_t iy) {
    ix %= img.width;
    iy %= img.height;
    if (ix < 0) ix += img.width;
    if (iy < 0) iy += img.height;
    return glm::max(img.texels[static_cast<size_t>(iy) * img.width + ix], Rgb(0.f));  // pbrt clamps negatives
  };
  int32_t ix = static_cast<int32_t>(fx), iy = static_cast<int32_t>(fy);
  return (1.f - dx) * (1.f - dy) * texel(ix, iy) + dx * (1.f - dy) * texel(ix + 1, iy) +
         (1.f - dx) * dy * texel(ix, iy + 1) + dx * dy * texel(ix + 1, iy + 1);
}

// Nearest-texel lookup in an equal-area octahedral environment map (pbrt-v4
// ImageInfiniteLight::ImageLe): uv (0,0) is the top-left texel, no flip.
TESSERA_HOST_DEVICE inline Rgb image_lookup_nearest_equal_area(const ImageView& img, Vec2 uv) {
  Float fx = glm::clamp(uv.x, 0.f, 1.f) * img.width, fy = glm::clamp(uv.y, 0.f, 1.f) * img.height;
  if (!(fx >= 0.f)) fx = 0.f;  // NaN
  if (!(fy >= 0.f)) fy = 0.f;
  int32_t x = glm::min(static_cast<int32_t>(fx), img.width - 1);
  int32_t y = glm::min(static_cast<int32_t>(fy), img.height - 1);
  return glm::max(img.texels[static_cast<size_t>(y) * img.width + x], Rgb(0.f));  // pbrt clamps negatives
}

// Textures may nest (scale of a checkerboard of images...). The recursion
// terminates because the loader only lets a texture reference earlier ones.
TESSERA_HOST_DEVICE inline Rgb eval_texture(const SceneView& s, int32_t tex_index, Vec2 uv) {
  const Texture& t = s.textures[tex_index];
  Vec2 st(t.su * uv.x + t.du, t.sv * uv.y + t.dv);
  switch (t.type) {
    case TextureType::Constant:
      return t.value;
    case TextureType::Image: {
      Rgb v = image_bilerp(s.images[t.image], st) * t.scale;
      return t.invert ? glm::max(Rgb(0.f), Rgb(1.f) - v) : v;
    }
    case TextureType::Scale: {
      Rgb a = t.a.texture >= 0 ? eval_texture(s, t.a.texture, uv) : t.a.value;
      Rgb b = t.b.texture >= 0 ? eval_texture(s, t.b.texture, uv) : t.b.value;
      return a * b;
    }
    case TextureType::Checkerboard: {
      // Parity of floor(s) + floor(t), computed in float so huge or NaN st cannot overflow a cast.
      Float sum = glm::floor(st.x) + glm::floor(st.y);
      Float half = sum * 0.5f;
      int64_t parity = (half == glm::floor(half)) ? 0 : 1;
      const TextureSlot& pick = (parity % 2 == 0) ? t.a : t.b;
      return pick.texture >= 0 ? eval_texture(s, pick.texture, uv) : pick.value;
    }
    case TextureType::Mix: {  // pbrt-v4 MixTexture: a component with weight 0 is not evaluated
      const Float amt = (t.amount.texture >= 0 ? eval_texture(s, t.amount.texture, uv) : t.amount.value).x;
      Rgb v(0.f);
      if (amt != 1.f) v += (1.f - amt) * (t.a.texture >= 0 ? eval_texture(s, t.a.texture, uv) : t.a.value);
      if (amt != 0.f) v += amt * (t.b.texture >= 0 ? eval_texture(s, t.b.texture, uv) : t.b.value);
      return v;
    }
    case TextureType::Bilerp:  // corners v00, v01, v10, v11 at (s, t) = (0,0), (0,1), (1,0), (1,1)
      return (1.f - st.x) * (1.f - st.y) * t.corners[0] + (1.f - st.x) * st.y * t.corners[1] +
             st.x * (1.f - st.y) * t.corners[2] + st.x * st.y * t.corners[3];
  }
  return Rgb(0.f);
}

TESSERA_HOST_DEVICE inline Rgb eval_slot(const SceneView& s, const TextureSlot& slot, Vec2 uv) {
  return slot.texture >= 0 ? eval_texture(s, slot.texture, uv) : slot.value;
}

}  // namespace tessera
