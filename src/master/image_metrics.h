// Error metrics between a rendered image and a reference.
#pragma once

#include <cstdint>

#include "master/film.h"

namespace tessera {

// relMSE's regulariser: keeps near-black reference pixels from dominating.
constexpr double kRelMseEpsilon = 1e-2;

struct ImageErrors {
  double rel_mse = 0;   // mean over pixels and channels of (A-F)^2 / (F^2 + kRelMseEpsilon)
  double mape = 0;      // mean over pixels of |A-F|/A on luminance, skipping A = 0
  double rmse = 0;
  uint64_t nonfinite_pixels = 0;  // pixels of the image with a NaN/Inf channel (excluded from the metrics)
  uint64_t reference_nonfinite_pixels = 0;
  uint64_t pixels = 0;
  double mean_image[3] = {0, 0, 0};      // channel means over finite pixels: brightness at a glance
  double mean_reference[3] = {0, 0, 0};
};

// Throws std::invalid_argument when the sizes differ.
ImageErrors compare_images(const ImageRgb& image, const ImageRgb& reference);

}  // namespace tessera
