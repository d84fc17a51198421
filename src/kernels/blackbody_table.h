// The film's RGB of pbrt-v4's peak-normalised blackbody spectrum,
// B(lambda, T) / B(lambda_max, T), for grid media that glow by temperature
// under RGB transport (spectral transport evaluates Planck's law at the
// path's wavelengths instead). Tabulated over log T as the luminance (read
// log-linearly: it spans tens of decades below 1000 K) and the colour per
// unit luminance (read linearly: it changes slowly).
#pragma once

#include "vecmath.h"

namespace tessera {

constexpr int32_t kBlackbodyTableSize = 1024;
constexpr Float kBlackbodyTableMinKelvin = 100.f, kBlackbodyTableMaxKelvin = 100000.f;

// Entry i's temperature.
TESSERA_HOST_DEVICE inline Float blackbody_table_kelvin(int32_t i) {
  return kBlackbodyTableMinKelvin *
         glm::pow(kBlackbodyTableMaxKelvin / kBlackbodyTableMinKelvin, static_cast<Float>(i) / (kBlackbodyTableSize - 1));
}

// table: kBlackbodyTableSize entries of (log luminance, r / Y, g / Y, b / Y).
TESSERA_HOST_DEVICE inline Rgb blackbody_table_rgb(const Float* table, Float kelvin) {
  if (!table || !(kelvin > kBlackbodyTableMinKelvin)) return Rgb(0.f);
  const Float x = glm::log(kelvin / kBlackbodyTableMinKelvin) /
                  glm::log(kBlackbodyTableMaxKelvin / kBlackbodyTableMinKelvin) * (kBlackbodyTableSize - 1);
  if (!(x < kBlackbodyTableSize - 1)) {
    // Past the table B / B(peak) falls as T^-4 in the visible (Rayleigh-Jeans over Wien's peak).
    const Float* e = table + 4 * (kBlackbodyTableSize - 1);
    const Float r = kBlackbodyTableMaxKelvin / kelvin;
    return glm::exp(e[0]) * (r * r) * (r * r) * Rgb(e[1], e[2], e[3]);
  }
  const int32_t i = static_cast<int32_t>(x);
  const Float f = x - i;
  const Float* a = table + 4 * i;
  const Float* b = a + 4;
  const Float y = glm::exp(a[0] + f * (b[0] - a[0]));
  return y * Rgb(a[1] + f * (b[1] - a[1]), a[2] + f * (b[2] - a[2]), a[3] + f * (b[3] - a[3]));
}

}  // namespace tessera
