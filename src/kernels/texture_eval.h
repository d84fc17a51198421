// Evaluating textures at a surface point (point sampling; no ray differentials yet).
#pragma once

#include "scene_view.h"
#include "vecmath.h"

namespace tessera {

TESSERA_HOST_DEVICE inline Rgb image_bilerp(const ImageView& img, Vec2 st) {
  // pbrt-v4 flips t for image lookups and wraps with "repeat".
  Float x = st.x * img.width - 0.5f, y = (1.f - st.y) * img.height - 0.5f;
  Float fx = glm::floor(x), fy = glm::floor(y);
  Float dx = x - fx, dy = y - fy;
  auto texel = [&](int32_t ix, int32_t iy) {
    ix %= img.width;
    iy %= img.height;
    if (ix < 0) ix += img.width;
    if (iy < 0) iy += img.height;
    return img.texels[static_cast<size_t>(iy) * img.width + ix];
  };
  int32_t ix = static_cast<int32_t>(fx), iy = static_cast<int32_t>(fy);
  return (1.f - dx) * (1.f - dy) * texel(ix, iy) + dx * (1.f - dy) * texel(ix + 1, iy) +
         (1.f - dx) * dy * texel(ix, iy + 1) + dx * dy * texel(ix + 1, iy + 1);
}

// Nearest-texel lookup in an equal-area octahedral environment map (pbrt-v4
// ImageInfiniteLight::ImageLe): uv (0,0) is the top-left texel, no flip.
TESSERA_HOST_DEVICE inline Rgb image_lookup_nearest_equal_area(const ImageView& img, Vec2 uv) {
  int32_t x = glm::clamp(static_cast<int32_t>(uv.x * img.width), 0, img.width - 1);
  int32_t y = glm::clamp(static_cast<int32_t>(uv.y * img.height), 0, img.height - 1);
  return img.texels[static_cast<size_t>(y) * img.width + x];
}

// Textures may nest (scale of a checkerboard of images...). Nesting depth is
// bounded by the loader's texture order (a texture only references earlier
// ones), so this terminates; an explicit stack keeps it GPU-friendly.
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
      int64_t parity = static_cast<int64_t>(glm::floor(st.x)) + static_cast<int64_t>(glm::floor(st.y));
      const TextureSlot& pick = (parity % 2 == 0) ? t.a : t.b;
      return pick.texture >= 0 ? eval_texture(s, pick.texture, uv) : pick.value;
    }
  }
  return Rgb(0.f);
}

TESSERA_HOST_DEVICE inline Rgb eval_slot(const SceneView& s, const TextureSlot& slot, Vec2 uv) {
  return slot.texture >= 0 ? eval_texture(s, slot.texture, uv) : slot.value;
}

}  // namespace tessera
