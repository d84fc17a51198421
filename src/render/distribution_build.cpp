#include "render/distribution_build.h"

#include <cmath>

namespace tessera {

Distribution1D::Distribution1D(std::vector<Float> f) : func(std::move(f)) {
  if (func.empty()) func.push_back(0.f);
  const size_t n = func.size();
  cdf.assign(n + 1, 0.f);
  // Accumulate in double so long tables keep a monotone, accurate cdf.
  double acc = 0.0;
  for (size_t i = 0; i < n; ++i) {
    if (!(func[i] > 0.f) || !std::isfinite(func[i])) func[i] = 0.f;
    acc += func[i];
  }
  integral = static_cast<Float>(acc / n);
  double run = 0.0;
  for (size_t i = 0; i < n; ++i) {
    run += (acc > 0.0) ? func[i] / acc : 1.0 / n;
    cdf[i + 1] = static_cast<Float>(run);
  }
  cdf[n] = 1.f;
}

Distribution2D::Distribution2D(const std::vector<Float>& f, uint32_t w, uint32_t h) : width(w), height(h) {
  func = f;
  cond_cdf.resize(static_cast<size_t>(h) * (w + 1));
  cond_integral.resize(h);
  std::vector<Float> row_integrals(h);
  for (uint32_t y = 0; y < h; ++y) {
    Distribution1D row(std::vector<Float>(f.begin() + static_cast<size_t>(y) * w, f.begin() + static_cast<size_t>(y + 1) * w));
    std::copy(row.func.begin(), row.func.end(), func.begin() + static_cast<size_t>(y) * w);
    std::copy(row.cdf.begin(), row.cdf.end(), cond_cdf.begin() + static_cast<size_t>(y) * (w + 1));
    cond_integral[y] = row.integral;
    row_integrals[y] = row.integral;
  }
  marginal = Distribution1D(row_integrals);
}

Distribution2DView Distribution2D::view() const {
  Distribution2DView v;
  v.func = func.data();
  v.cond_cdf = cond_cdf.data();
  v.cond_integral = cond_integral.data();
  v.marginal = marginal.view();
  v.width = width;
  v.height = height;
  return v;
}

}  // namespace tessera
