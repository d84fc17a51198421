#include "render/film.h"

#include <algorithm>
#include <stdexcept>

namespace tessera {

void film_add_splats(Film& film, const std::vector<Splat>& splats, uint64_t light_paths) {
  film.light_paths += light_paths;
  if (splats.empty()) return;
  if (film.splats.empty()) film.splats.resize(film.pixels.size());
  for (const Splat& s : splats) {
    if (s.pixel >= film.splats.size()) throw std::runtime_error("light path splat outside the image");
    SplatAccum& a = film.splats[s.pixel];
    for (int c = 0; c < 3; ++c) {
      a.sum[c] += s.value[c];
      a.sum_sq[c] += static_cast<double>(s.value[c]) * s.value[c];
    }
  }
}

PixelEstimate pixel_estimate(const Film& film, size_t i, int c) {
  PixelEstimate e;
  const PixelAccum& p = film.pixels[i];
  if (p.n > 0) e.mean = p.sum[c] / p.n;
  if (p.n > 1) {
    // Unbiased sample variance from the double sums; rounding can make it slightly negative.
    const double n = static_cast<double>(p.n);
    e.var_of_mean = std::max(0.0, (p.sum_sq[c] - p.sum[c] * e.mean) / (n - 1.0)) / n;
  }
  if (!film.splats.empty() && film.light_paths > 1) {
    const SplatAccum& s = film.splats[i];
    const double n = static_cast<double>(film.light_paths);
    const double mean = s.sum[c] / n;
    e.mean += mean;
    e.var_of_mean += std::max(0.0, (s.sum_sq[c] - s.sum[c] * mean) / (n - 1.0)) / n;
  }
  return e;
}

ImageRgb film_mean(const Film& film) {
  ImageRgb img{film.width, film.height, std::vector<float>(film.pixels.size() * 3, 0.f)};
  for (size_t i = 0; i < film.pixels.size(); ++i)
    for (int c = 0; c < 3; ++c) img.rgb[3 * i + c] = static_cast<float>(pixel_estimate(film, i, c).mean);
  return img;
}

ImageRgb film_variance_of_mean(const Film& film) {
  ImageRgb img{film.width, film.height, std::vector<float>(film.pixels.size() * 3, 0.f)};
  for (size_t i = 0; i < film.pixels.size(); ++i) {
    if (film.pixels[i].n < 2) continue;
    for (int c = 0; c < 3; ++c) {
      // A variance beyond float's range (radiance ~1e20 and up) is stored as
      // the largest float: saturated, not infinite (variance_saturated_pixels()).
      const double v = pixel_estimate(film, i, c).var_of_mean;
      img.rgb[3 * i + c] = v < kVarianceSaturated ? static_cast<float>(v) : kVarianceSaturated;
    }
  }
  return img;
}

uint64_t variance_saturated_pixels(const ImageRgb& variance) {
  uint64_t n = 0;
  for (size_t i = 0; i + 2 < variance.rgb.size(); i += 3)
    n += !(variance.rgb[i] < kVarianceSaturated && variance.rgb[i + 1] < kVarianceSaturated &&
           variance.rgb[i + 2] < kVarianceSaturated);
  return n;
}

}  // namespace tessera
