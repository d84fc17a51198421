#include "master/image_metrics.h"

#include <cmath>
#include <stdexcept>
#include <string>

namespace tessera {

ImageErrors compare_images(const ImageRgb& img, const ImageRgb& ref) {
  if (img.width != ref.width || img.height != ref.height) {
    throw std::invalid_argument("image sizes differ: " + std::to_string(img.width) + "x" + std::to_string(img.height) +
                                " vs reference " + std::to_string(ref.width) + "x" + std::to_string(ref.height));
  }
  ImageErrors e;
  const size_t n = static_cast<size_t>(img.width) * img.height;
  e.pixels = n;
  double rel = 0, sq = 0, ape = 0;
  uint64_t counted = 0, mape_count = 0;
  for (size_t i = 0; i < n; ++i) {
    const float* a = &img.rgb[3 * i];
    const float* f = &ref.rgb[3 * i];
    bool bad_a = !std::isfinite(a[0]) || !std::isfinite(a[1]) || !std::isfinite(a[2]);
    bool bad_f = !std::isfinite(f[0]) || !std::isfinite(f[1]) || !std::isfinite(f[2]);
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
    double ya = 0.2126 * f[0] + 0.7152 * f[1] + 0.0722 * f[2];
    double yf = 0.2126 * a[0] + 0.7152 * a[1] + 0.0722 * a[2];
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

}  // namespace tessera
