#include "master/film.h"

namespace tessera {

ImageRgb film_mean(const Film& film) {
  ImageRgb img{film.width, film.height, std::vector<float>(film.pixels.size() * 3, 0.f)};
  for (size_t i = 0; i < film.pixels.size(); ++i) {
    const PixelAccum& p = film.pixels[i];
    if (p.n == 0) continue;
    for (int c = 0; c < 3; ++c) img.rgb[3 * i + c] = static_cast<float>(p.sum[c] / p.n);
  }
  return img;
}

ImageRgb film_variance_of_mean(const Film& film) {
  ImageRgb img{film.width, film.height, std::vector<float>(film.pixels.size() * 3, 0.f)};
  for (size_t i = 0; i < film.pixels.size(); ++i) {
    const PixelAccum& p = film.pixels[i];
    if (p.n < 2) continue;
    for (int c = 0; c < 3; ++c) {
      double mean = p.sum[c] / p.n;
      double var = (p.sum_sq[c] / p.n - mean * mean) * p.n / (p.n - 1);  // unbiased sample variance
      img.rgb[3 * i + c] = static_cast<float>(var > 0 ? var / p.n : 0.0);
    }
  }
  return img;
}

}  // namespace tessera
