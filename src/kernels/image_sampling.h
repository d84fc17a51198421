// Reading an image at continuous coordinates, as pbrt-v4's Image does:
// bilinear (Image::Bilerp) or nearest (the "point" filter) lookups with a
// wrap mode for coordinates outside [0, 1], and the nearest-texel lookup of
// equal-area environment maps.
#pragma once

#include "device.h"
#include "material.h"

namespace tessera {

// pbrt-v4's RemapPixelCoords: moves texel (x, y) into the image, or returns
// false where the wrap mode reads black there.
TESSERA_HOST_DEVICE inline bool wrap_texel(int32_t* x, int32_t* y, int32_t w, int32_t h, ImageWrap wrap) {
  if (wrap == ImageWrap::OctahedralSphere) {
    // Mirrored across the square's edges, as the equal-area octahedral map
    // continues across them.
    if (*x < 0) {
      *x = -*x;
      *y = h - 1 - *y;
    } else if (*x >= w) {
      *x = 2 * w - 1 - *x;
      *y = h - 1 - *y;
    }
    if (*y < 0) {
      *x = w - 1 - *x;
      *y = -*y;
    } else if (*y >= h) {
      *x = w - 1 - *x;
      *y = 2 * h - 1 - *y;
    }
    // Lookups reach at most one texel past an edge; clamping keeps anything
    // further (pbrt-v4 does not guard it) inside the image.
    *x = glm::clamp(*x, 0, w - 1);
    *y = glm::clamp(*y, 0, h - 1);
    return true;
  }
  if (*x < 0 || *x >= w || *y < 0 || *y >= h) {
    if (wrap == ImageWrap::Black) return false;
    if (wrap == ImageWrap::Clamp) {
      *x = glm::clamp(*x, 0, w - 1);
      *y = glm::clamp(*y, 0, h - 1);
    } else {  // Repeat
      *x %= w;
      *y %= h;
      if (*x < 0) *x += w;
      if (*y < 0) *y += h;
    }
  }
  return true;
}

TESSERA_HOST_DEVICE inline Rgb image_texel(const ImageView& img, int32_t x, int32_t y, ImageWrap wrap) {
  if (!wrap_texel(&x, &y, img.width, img.height, wrap)) return Rgb(0.f);
  return glm::max(img.texels[static_cast<size_t>(y) * img.width + x], Rgb(0.f));  // pbrt clamps negatives
}

// Keeps st where the integer conversions below cannot overflow (NaN -> 0)
// without changing any lookup: "repeat" wraps in float, the other modes read
// the same texels anywhere beyond one image width outside [0, 1].
TESSERA_HOST_DEVICE inline Vec2 bounded_st(Vec2 st, ImageWrap wrap) {
  if (wrap == ImageWrap::Repeat) st = st - glm::floor(st);
  else st = glm::clamp(st, Vec2(-1.f), Vec2(2.f));
  if (!(st.x >= -1.f && st.x <= 2.f)) st.x = 0.f;
  if (!(st.y >= -1.f && st.y <= 2.f)) st.y = 0.f;
  return st;
}

// A texture lookup: t flipped (row 0 is the top of the file), then pbrt-v4's
// Bilerp or, for the "point" filter, the nearest texel.
TESSERA_HOST_DEVICE inline Rgb image_lookup(const ImageView& img, Vec2 st, ImageWrap wrap = ImageWrap::Repeat,
                                            ImageFilter filter = ImageFilter::Bilinear) {
  st = bounded_st(st, wrap);
  const Float x = st.x * img.width - 0.5f, y = (1.f - st.y) * img.height - 0.5f;
  if (filter == ImageFilter::Point)
    return image_texel(img, static_cast<int32_t>(glm::round(x)), static_cast<int32_t>(glm::round(y)), wrap);
  const Float fx = glm::floor(x), fy = glm::floor(y);
  const Float dx = x - fx, dy = y - fy;
  const int32_t ix = static_cast<int32_t>(fx), iy = static_cast<int32_t>(fy);
  return (1.f - dx) * (1.f - dy) * image_texel(img, ix, iy, wrap) + dx * (1.f - dy) * image_texel(img, ix + 1, iy, wrap) +
         (1.f - dx) * dy * image_texel(img, ix, iy + 1, wrap) + dx * dy * image_texel(img, ix + 1, iy + 1, wrap);
}

// pbrt-v4's Image::LookupNearest, clamped: uv (0,0) is the top-left texel,
// no flip (equal-area environment maps, goniometric and projection lights).
TESSERA_HOST_DEVICE inline Rgb image_lookup_nearest(const ImageView& img, Vec2 uv) {
  Float fx = glm::clamp(uv.x, 0.f, 1.f) * img.width, fy = glm::clamp(uv.y, 0.f, 1.f) * img.height;
  if (!(fx >= 0.f)) fx = 0.f;  // NaN
  if (!(fy >= 0.f)) fy = 0.f;
  int32_t x = glm::min(static_cast<int32_t>(fx), img.width - 1);
  int32_t y = glm::min(static_cast<int32_t>(fy), img.height - 1);
  return glm::max(img.texels[static_cast<size_t>(y) * img.width + x], Rgb(0.f));  // pbrt clamps negatives
}

}  // namespace tessera
