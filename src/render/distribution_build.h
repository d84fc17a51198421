// Host-side storage for the piecewise-constant distributions in kernels/distribution.h.
#pragma once

#include <vector>

#include "kernels/distribution.h"

namespace tessera {

struct Distribution1D {
  std::vector<Float> func, cdf;
  Float integral = 0.f;

  // Negative or non-finite entries are treated as 0. An all-zero function
  // gets a uniform cdf (so sampling still works) and integral 0.
  explicit Distribution1D(std::vector<Float> f = {Float(0)});
  Distribution1DView view() const {
    return Distribution1DView{func.data(), cdf.data(), static_cast<uint32_t>(func.size()), integral};
  }
};

struct Distribution2D {
  uint32_t width = 0, height = 0;
  std::vector<Float> func, cond_cdf, cond_integral;
  Distribution1D marginal;

  Distribution2D() = default;
  Distribution2D(const std::vector<Float>& f, uint32_t width, uint32_t height);
  Distribution2DView view() const;
};

}  // namespace tessera
