// Image statistics shared by the GoogleTest binaries and the GPU check
// program (which has no GoogleTest): per-channel means of a film and their
// standard errors.
#pragma once

#include <cmath>

#include "render/film.h"

namespace tessera::testing {

// Per-channel image means and their standard errors. Pixels are independent
// given the guide, and each pass's samples are unbiased given the field they
// were drawn with, so the variance of a channel's mean over N pixels is
// sum_i var_i / N^2 with var_i the variance of pixel i's mean. Channels are
// compared separately: the three channels of one path are strongly
// correlated, and pooling them as if independent would understate the error.
struct ChannelStats {
  double mean[3] = {0, 0, 0};
  double se[3] = {0, 0, 0};
};

// In double from the film's sums: the float images saturate variances
// beyond float's range (radiance ~1e20 and up), which would understate them.
inline ChannelStats channel_stats(const Film& film) {
  const double n = static_cast<double>(film.pixels.size());
  ChannelStats s;
  for (int c = 0; c < 3; ++c) {
    double sum = 0, var = 0;
    for (size_t i = 0; i < film.pixels.size(); ++i) {
      const PixelEstimate e = pixel_estimate(film, i, c);
      sum += e.mean;
      var += e.var_of_mean;
    }
    s.mean[c] = sum / n;
    s.se[c] = std::sqrt(var) / n;
  }
  return s;
}

}  // namespace tessera::testing
