// The host side of spectral transport: the CIE tables, the sRGB matrix and
// the RGB-to-spectrum table (generated at build time and embedded in the
// binary), as a kernels/spectral.h SpectralView.
#pragma once

#include <vector>

#include "kernels/spectral.h"

namespace tessera {

struct SpectralTables {
  std::vector<Float> cmf;         // [kSpectralSamples][3]
  std::vector<Float> illuminant;  // [kSpectralSamples], D65 with luminance 1
  const float* scale = nullptr;   // [res], embedded
  const float* coeffs = nullptr;  // [3][res][res][res][3], embedded
  int32_t res = 0;
  Mat3 rgb_from_xyz{1.f};
  Float inv_y_integral = 0.f;

  SpectralView view() const;  // enabled
};

// The sRGB tables (pbrt-v4's default colour space). Throws if the embedded
// table is damaged (a broken build).
const SpectralTables& srgb_spectral_tables();

}  // namespace tessera
