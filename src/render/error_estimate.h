// The image's error estimated from the film alone, while rendering: no
// reference needed. Each pixel's sample variance gives the variance of its
// mean; summed as compare_images sums squared errors, that is the expected
// relMSE of the current image against the converged one.
#pragma once

#include <cstdint>

#include "render/film.h"

namespace tessera {

// Samples per pixel below which the estimate is not given: a sample
// variance from fewer samples is too noisy to stop a render on.
constexpr uint64_t kMinSppForErrorEstimate = 4;

struct ErrorEstimate {
  bool valid = false;    // false below kMinSppForErrorEstimate samples in some pixel, or with unusable pixels
  double rel_mse = 0.0;  // estimated relMSE of film_mean(film) (the metric of compare_images)
  // From images: pixels whose mean is not finite or whose variance is
  // negative, NaN or saturated (film_variance_of_mean); any makes it invalid.
  uint64_t unusable_pixels = 0;
};

// relMSE = mean over pixels and channels of Var[mean] / (F^2 + eps), with
// Var[mean] the unbiased sample variance / n, and F^2 estimated as
// mean^2 - Var[mean] (at least 0): a pixel lit by one rare bright sample
// counts as noisy, not as bright. Each factor is unbiased; their ratio is
// not quite, and the bias fades as 1/n: at 4-16 spp the estimate runs
// ~5-20 % low on smooth (furnace-like) images and up to a few times high
// where a few bright samples light a pixel (the clamp above); from ~64 spp
// it is close. Guided renders pool passes with different (all unbiased)
// estimators, which the sample variance handles.
ErrorEstimate estimate_rel_mse(const Film& film);

// The same from an image and the variance of its mean (the variance layer
// of a Tessera EXR): e.g. how noisy a reference itself still is. Pixels
// with a NaN/Inf channel are skipped. Throws std::invalid_argument when
// the sizes differ.
ErrorEstimate estimate_rel_mse(const ImageRgb& mean, const ImageRgb& variance_of_mean);

}  // namespace tessera
