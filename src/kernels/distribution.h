// Piecewise-constant 1D and 2D distributions over read-only views, for
// importance sampling lights and environment maps. Built on the host
// (src/render/distribution_build.h), sampled on either side.
#pragma once

#include "vecmath.h"

namespace tessera {

// func has n entries >= 0; cdf has n + 1 entries with cdf[0] = 0 and cdf[n] = 1.
// integral is the mean of func (so pdf(x) = func[i] / integral over [0,1)).
struct Distribution1DView {
  const Float* func = nullptr;
  const Float* cdf = nullptr;
  uint32_t n = 0;
  Float integral = 0.f;

  // Largest index i with cdf[i] <= u (binary search), so that u lands in bin i.
  TESSERA_HOST_DEVICE uint32_t find_bin(Float u) const {
    uint32_t lo = 0, hi = n;  // invariant: cdf[lo] <= u < cdf[hi]
    while (hi - lo > 1) {
      uint32_t mid = (lo + hi) >> 1;
      if (cdf[mid] <= u) lo = mid; else hi = mid;
    }
    return lo;
  }
  // Discrete sampling: returns the bin, its probability in *pmf.
  TESSERA_HOST_DEVICE uint32_t sample_discrete(Float u, Float* pmf) const {
    uint32_t i = find_bin(u);
    if (pmf) *pmf = cdf[i + 1] - cdf[i];
    return i;
  }
  TESSERA_HOST_DEVICE Float discrete_pmf(uint32_t i) const { return cdf[i + 1] - cdf[i]; }
  // Continuous sampling over [0,1): returns x, the density in *pdf and the bin in *bin.
  TESSERA_HOST_DEVICE Float sample_continuous(Float u, Float* pdf, uint32_t* bin) const {
    uint32_t i = find_bin(u);
    Float width = cdf[i + 1] - cdf[i];
    Float du = width > 0.f ? (u - cdf[i]) / width : 0.f;
    if (pdf) *pdf = integral > 0.f ? func[i] / integral : 0.f;
    if (bin) *bin = i;
    Float x = (static_cast<Float>(i) + du) / static_cast<Float>(n);
    return glm::min(x, 0x1.fffffep-1f);
  }
  TESSERA_HOST_DEVICE Float pdf_continuous(Float x) const {
    if (integral <= 0.f) return 0.f;
    uint32_t i = glm::min(static_cast<uint32_t>(glm::max(x, 0.f) * n), n - 1);
    return func[i] / integral;
  }
};

// Rows are conditional distributions over u (width bins), the marginal is over v.
struct Distribution2DView {
  const Float* func = nullptr;       // height * width
  const Float* cond_cdf = nullptr;   // height * (width + 1)
  const Float* cond_integral = nullptr;  // height
  Distribution1DView marginal;       // over rows
  uint32_t width = 0, height = 0;

  TESSERA_HOST_DEVICE Distribution1DView row(uint32_t v) const {
    Distribution1DView d;
    d.func = func + static_cast<size_t>(v) * width;
    d.cdf = cond_cdf + static_cast<size_t>(v) * (width + 1);
    d.n = width;
    d.integral = cond_integral[v];
    return d;
  }
  // Returns (u, v) in [0,1)^2 and the density with respect to area in [0,1]^2.
  TESSERA_HOST_DEVICE Vec2 sample(Vec2 u, Float* pdf) const {
    Float pdf_v, pdf_u;
    uint32_t v_bin;
    Float y = marginal.sample_continuous(u.y, &pdf_v, &v_bin);
    Float x = row(v_bin).sample_continuous(u.x, &pdf_u, nullptr);
    *pdf = pdf_u * pdf_v;
    return Vec2(x, y);
  }
  TESSERA_HOST_DEVICE Float pdf(Vec2 p) const {
    if (marginal.integral <= 0.f) return 0.f;
    uint32_t iu = glm::min(static_cast<uint32_t>(glm::max(p.x, 0.f) * width), width - 1);
    uint32_t iv = glm::min(static_cast<uint32_t>(glm::max(p.y, 0.f) * height), height - 1);
    return func[static_cast<size_t>(iv) * width + iu] / marginal.integral;
  }
};

}  // namespace tessera
