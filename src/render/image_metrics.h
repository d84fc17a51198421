// Error metrics between a rendered image and a reference.
#pragma once

#include <cstdint>

#include "render/film.h"

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

// Block agreement: where an image's brightness departs from the reference's.
// Averages over B x B blocks wash out both images' Monte Carlo noise (a
// 256 spp reference is still noisy in caustics), so what is left is bias: a
// missing feature, a wrong material, a light too bright. Blocks are judged on
// mean luminance (Rec. 709 weights) over pixels finite in both images.
constexpr int32_t kDefaultBlockSize = 8;
// A block whose ratio is outside [1 - kBlockTolerance, 1 + kBlockTolerance] is "off".
constexpr double kBlockTolerance = 0.1;
// Blocks whose reference mean is below this fraction of the reference image's
// mean luminance are too dark to judge: their ratio is noise over near-zero.
constexpr double kBlockDarkFraction = 1e-3;

struct BlockAgreement {
  int32_t block = kDefaultBlockSize;  // block side in pixels; edge blocks may be smaller
  int32_t blocks_x = 0, blocks_y = 0;
  uint64_t judged_blocks = 0;  // blocks bright enough (and with finite pixels) to judge
  // image block mean / reference block mean of the judged block farthest from 1
  // (first in raster order on ties); 1 and (-1, -1) when no block was judged.
  double worst_ratio = 1.0;
  int32_t worst_x = -1, worst_y = -1;  // in blocks, (0, 0) = top left
  double fraction_off = 0;             // of the judged blocks, those with |ratio - 1| > kBlockTolerance
};

// Throws std::invalid_argument when the sizes differ or block < 1.
BlockAgreement compare_blocks(const ImageRgb& image, const ImageRgb& reference, int32_t block = kDefaultBlockSize);

}  // namespace tessera
