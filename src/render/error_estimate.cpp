#include "render/error_estimate.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "render/image_metrics.h"

namespace tessera {

namespace {

// One channel of one pixel: Var[mean] / (F^2 + eps), F^2 = mean^2 - Var[mean].
double rel_mse_term(double mean, double var_of_mean) {
  const double f2 = std::max(0.0, mean * mean - var_of_mean);
  return var_of_mean / (f2 + kRelMseEpsilon);
}

}  // namespace

ErrorEstimate estimate_rel_mse(const Film& film) {
  ErrorEstimate e;
  if (film.pixels.empty()) return e;
  double sum = 0.0;
  for (size_t i = 0; i < film.pixels.size(); ++i) {
    if (film.pixels[i].n < kMinSppForErrorEstimate) return e;
    for (int c = 0; c < 3; ++c) {
      const PixelEstimate p = pixel_estimate(film, i, c);
      sum += rel_mse_term(p.mean, p.var_of_mean);
    }
  }
  e.valid = std::isfinite(sum);
  e.rel_mse = sum / (3.0 * static_cast<double>(film.pixels.size()));
  return e;
}

ErrorEstimate estimate_rel_mse(const ImageRgb& mean, const ImageRgb& var) {
  if (mean.width != var.width || mean.height != var.height)
    throw std::invalid_argument("variance layer is " + std::to_string(var.width) + "x" + std::to_string(var.height) +
                                ", image " + std::to_string(mean.width) + "x" + std::to_string(mean.height));
  ErrorEstimate e;
  double sum = 0.0;
  uint64_t counted = 0;
  const size_t n = static_cast<size_t>(mean.width) * mean.height;
  for (size_t i = 0; i < n; ++i) {
    const float* m = &mean.rgb[3 * i];
    const float* v = &var.rgb[3 * i];
    bool usable = true;
    for (int c = 0; c < 3; ++c)
      usable = usable && std::isfinite(m[c]) && v[c] >= 0 && v[c] < kVarianceSaturated;  // NaN fails too
    if (!usable) {
      ++e.unusable_pixels;
      continue;
    }
    for (int c = 0; c < 3; ++c) sum += rel_mse_term(m[c], v[c]);
    ++counted;
  }
  // An estimate that leaves pixels out would pass for a low one: none then.
  e.valid = counted > 0 && e.unusable_pixels == 0;
  e.rel_mse = e.valid ? sum / (3.0 * static_cast<double>(counted)) : 0.0;
  return e;
}

}  // namespace tessera
