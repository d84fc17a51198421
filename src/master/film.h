// Per-pixel accumulators for the image being rendered. Each pixel is written
// by exactly one tile task at a time, in sample order, so sums are
// bit-identical whatever the thread count. Sums are double: a float sum of
// thousands of samples loses the low bits that later samples add.
#pragma once

#include <cstdint>
#include <vector>

#include "kernels/device.h"

namespace tessera {

struct PixelAccum {
  double sum[3] = {0, 0, 0};
  double sum_sq[3] = {0, 0, 0};
  uint64_t n = 0;
};

struct Film {
  int32_t width = 0, height = 0;
  std::vector<PixelAccum> pixels;

  Film() = default;
  Film(int32_t w, int32_t h) : width(w), height(h), pixels(static_cast<size_t>(w) * h) {}
  PixelAccum& at(int32_t x, int32_t y) { return pixels[static_cast<size_t>(y) * width + x]; }
  const PixelAccum& at(int32_t x, int32_t y) const { return pixels[static_cast<size_t>(y) * width + x]; }
};

// Final images derived from a film: the mean, and the variance of the mean.
struct ImageRgb {
  int32_t width = 0, height = 0;
  std::vector<float> rgb;  // 3 floats per pixel, row 0 = top
};

ImageRgb film_mean(const Film& film);
ImageRgb film_variance_of_mean(const Film& film);

}  // namespace tessera
