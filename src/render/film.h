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

// Light paths' contributions to a pixel (integrator/light_paths.h): sums over
// all light paths traced for the image, each path adding at most once.
struct SplatAccum {
  double sum[3] = {0, 0, 0};
  double sum_sq[3] = {0, 0, 0};
};

// One light path's contribution to one pixel (each path adds at most one
// per pixel). Padded explicitly: it travels and is saved as raw bytes.
struct Splat {
  uint64_t pixel = 0;  // y * width + x
  float value[3] = {0, 0, 0};
  uint32_t padding = 0;
};

struct Film {
  int32_t width = 0, height = 0;
  std::vector<PixelAccum> pixels;
  // Light-traced caustics: empty unless they are traced. A pixel's value is
  // its camera samples' mean plus its splat sum over light_paths.
  std::vector<SplatAccum> splats;
  uint64_t light_paths = 0;

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

// Adds a tile's splats, in their order, and the number of light paths it traced.
void film_add_splats(Film& film, const std::vector<Splat>& splats, uint64_t light_paths);

// Pixel i's estimate in channel c and the variance of that estimate (camera
// samples and light paths are independent: their variances add). Valid only
// with at least two camera samples.
struct PixelEstimate {
  double mean = 0.0;
  double var_of_mean = 0.0;
};
PixelEstimate pixel_estimate(const Film& film, size_t i, int c);

ImageRgb film_mean(const Film& film);
// Variances beyond float's range are stored as kVarianceSaturated.
ImageRgb film_variance_of_mean(const Film& film);

constexpr float kVarianceSaturated = 3.40282347e+38f;  // the largest float
// Pixels with a channel whose variance is saturated (or not a number).
uint64_t variance_saturated_pixels(const ImageRgb& variance);

}  // namespace tessera
