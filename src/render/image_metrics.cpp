#include "render/image_metrics.h"

#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

namespace tessera {

namespace {

void check_same_size(const ImageRgb& img, const ImageRgb& ref) {
  if (img.width != ref.width || img.height != ref.height) {
    throw std::invalid_argument("image sizes differ: " + std::to_string(img.width) + "x" + std::to_string(img.height) +
                                " vs reference " + std::to_string(ref.width) + "x" + std::to_string(ref.height));
  }
}

bool finite_pixel(const float* p) { return std::isfinite(p[0]) && std::isfinite(p[1]) && std::isfinite(p[2]); }

double luminance(const float* p) { return 0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2]; }

}  // namespace

ImageErrors compare_images(const ImageRgb& img, const ImageRgb& ref) {
  check_same_size(img, ref);
  ImageErrors e;
  const size_t n = static_cast<size_t>(img.width) * img.height;
  e.pixels = n;
  double rel = 0, sq = 0, ape = 0;
  uint64_t counted = 0, mape_count = 0;
  for (size_t i = 0; i < n; ++i) {
    const float* a = &img.rgb[3 * i];
    const float* f = &ref.rgb[3 * i];
    bool bad_a = !finite_pixel(a);
    bool bad_f = !finite_pixel(f);
    if (bad_a) ++e.nonfinite_pixels;
    if (bad_f) ++e.reference_nonfinite_pixels;
    if (bad_a || bad_f) continue;
    ++counted;
    for (int c = 0; c < 3; ++c) {
      e.mean_image[c] += a[c];
      e.mean_reference[c] += f[c];
      double d = static_cast<double>(a[c]) - f[c];
      rel += d * d / (static_cast<double>(f[c]) * f[c] + kRelMseEpsilon);
      sq += d * d;
    }
    // MAPE (seed thesis): |A - F| / A with A the reference, on luminance.
    double ya = luminance(f);
    double yf = luminance(a);
    if (ya > 0) {
      ape += std::abs(ya - yf) / ya;
      ++mape_count;
    }
  }
  if (counted > 0) {
    for (int c = 0; c < 3; ++c) {
      e.mean_image[c] /= counted;
      e.mean_reference[c] /= counted;
    }
    e.rel_mse = rel / (3.0 * counted);
    e.rmse = std::sqrt(sq / (3.0 * counted));
  }
  if (mape_count > 0) e.mape = ape / mape_count;
  return e;
}

BlockAgreement compare_blocks(const ImageRgb& img, const ImageRgb& ref, int32_t block) {
  check_same_size(img, ref);
  if (block < 1) throw std::invalid_argument("block size must be at least 1, got " + std::to_string(block));
  BlockAgreement b;
  b.block = block;
  b.blocks_x = (img.width + block - 1) / block;
  b.blocks_y = (img.height + block - 1) / block;
  // Per block: luminance sums of both images and the count of pixels finite in both.
  const size_t nblocks = static_cast<size_t>(b.blocks_x) * b.blocks_y;
  std::vector<double> sum_img(nblocks, 0.0), sum_ref(nblocks, 0.0);
  std::vector<uint64_t> count(nblocks, 0);
  double ref_total = 0;
  uint64_t ref_count = 0;
  for (int32_t y = 0; y < img.height; ++y) {
    for (int32_t x = 0; x < img.width; ++x) {
      const size_t i = static_cast<size_t>(y) * img.width + x;
      const float* a = &img.rgb[3 * i];
      const float* f = &ref.rgb[3 * i];
      if (!finite_pixel(a) || !finite_pixel(f)) continue;
      const size_t k = static_cast<size_t>(y / block) * b.blocks_x + x / block;
      sum_img[k] += luminance(a);
      sum_ref[k] += luminance(f);
      ++count[k];
      ref_total += luminance(f);
      ++ref_count;
    }
  }
  if (ref_count == 0) return b;
  const double dark = kBlockDarkFraction * (ref_total / ref_count);
  uint64_t off = 0;
  double worst_dev = -1;
  for (size_t k = 0; k < nblocks; ++k) {
    if (count[k] == 0) continue;
    const double mean_ref = sum_ref[k] / count[k];
    // <= 0 as well: an all-black reference makes the threshold 0.
    if (mean_ref < dark || mean_ref <= 0) continue;
    const double ratio = (sum_img[k] / count[k]) / mean_ref;
    const double dev = std::abs(ratio - 1.0);
    ++b.judged_blocks;
    if (dev > kBlockTolerance) ++off;
    if (dev > worst_dev) {
      worst_dev = dev;
      b.worst_ratio = ratio;
      b.worst_x = static_cast<int32_t>(k % b.blocks_x);
      b.worst_y = static_cast<int32_t>(k / b.blocks_x);
    }
  }
  if (b.judged_blocks > 0) b.fraction_off = static_cast<double>(off) / b.judged_blocks;
  return b;
}

}  // namespace tessera
