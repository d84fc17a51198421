// Spectral transport as pbrt-v4 does it, carried in the kernels' Rgb type.
//
// In spectral mode a path carries its radiance at three wavelengths instead
// of three RGB channels: the components of every Rgb along the path are
// values at wl.lambda[0..2]. Colours enter a path only through a few doors
// (material reflectances, conductor and medium coefficients, emission), and
// each door converts the scene's RGB to the spectrum pbrt-v4 would use:
//   * albedo (reflectances, clamped to [0,1]): the smooth sigmoid spectrum of
//     Jakob & Hanika (2019) whose colour under D65 is the RGB;
//   * unbounded (eta, k, sigma_a, sigma_s): 2 max(rgb) times the albedo
//     spectrum of rgb / (2 max(rgb));
//   * illuminant (emission): the unbounded spectrum times the colour space's
//     illuminant (D65, normalised to luminance 1).
// The film turns a sample back into RGB through the CIE 1931 matching
// functions (XYZ) and the sRGB matrix. Three wavelengths per path where
// pbrt-v4 uses four: the estimator is the same, with a little more colour noise.
//
// The three wavelengths are stratified over the visible range by one random
// number (pbrt-v4's SampleVisibleWavelengths density, which follows the
// luminance response). At the first dispersive surface the path continues
// at one of its wavelengths, picked uniformly, with 3 times the throughput,
// and the others' throughput ends (dispersion_channel). Light gathered
// before stays in all three. (pbrt-v4 instead drops the other wavelengths'
// whole estimate, retroactively, which is unbiased only if no earlier
// decision weighs the wavelengths unequally; here luminance-weighted lobe
// and roulette choices would bias it.)
#pragma once

#include "vecmath.h"

namespace tessera {

// Tabulated spectra and the RGB-to-spectrum table, valid where they point.
// Wavelengths are in nm; tables are sampled at 360 + 5 i nm, i < kSpectralSamples.
constexpr int32_t kSpectralSamples = 95;
constexpr Float kLambdaMin = 360.f, kLambdaMax = 830.f;

struct SpectralView {
  bool enabled = false;                 // false: paths carry RGB and nothing here is read
  const Float* cmf = nullptr;           // [kSpectralSamples][3]: CIE 1931 x-bar, y-bar, z-bar
  const Float* illuminant = nullptr;    // [kSpectralSamples]: D65 scaled to luminance 1
  const Float* table_scale = nullptr;   // [res]: the brightness axis of the table
  const Float* table = nullptr;         // [3][res][res][res][3]: sigmoid coefficients (nm)
  int32_t res = 0;
  Mat3 rgb_from_xyz{1.f};               // linear sRGB from XYZ (D65 white of these tables)
  Float inv_y_integral = 0.f;           // 1 / integral of y-bar
};

struct Wavelengths {
  Vec3 lambda{550.f};
  Vec3 pdf{1.f};        // per nm
  int32_t single = -1;  // after a dispersive surface: the one wavelength the path continues at
};

// pbrt-v4's visible-wavelength density (integrates to 1 over 360-830 nm).
TESSERA_HOST_DEVICE inline Float visible_wavelength_pdf(Float lambda) {
  if (!(lambda >= kLambdaMin && lambda <= kLambdaMax)) return 0.f;
  const Float c = glm::cosh(0.0072f * (lambda - 538.f));
  return 0.0039398042f / (c * c);
}

TESSERA_HOST_DEVICE inline Float sample_visible_wavelength(Float u) {
  return 538.f - 138.888889f * glm::atanh(0.85691062f - 1.82750197f * u);
}

// Three wavelengths from one number: u, u + 1/3, u + 2/3 (mod 1).
TESSERA_HOST_DEVICE TESSERA_DEVICE_NOINLINE inline Wavelengths sample_wavelengths(Float u) {
  Wavelengths wl;
  for (int i = 0; i < 3; ++i) {
    Float ui = u + static_cast<Float>(i) / 3.f;
    if (ui >= 1.f) ui -= 1.f;
    wl.lambda[i] = glm::clamp(sample_visible_wavelength(ui), kLambdaMin, kLambdaMax);
    wl.pdf[i] = visible_wavelength_pdf(wl.lambda[i]);
  }
  return wl;
}

// The wavelength a dispersive surface scatters at: the path's one remaining
// wavelength, or, at its first dispersive surface, one of the three picked by
// u in [0,1) (the caller then multiplies that channel's throughput by 3 and
// zeroes the others': dispersion_mask).
TESSERA_HOST_DEVICE inline int32_t dispersion_channel(Wavelengths& wl, Float u) {
  if (wl.single < 0) wl.single = glm::min(static_cast<int32_t>(u * 3.f), 2);
  return wl.single;
}

TESSERA_HOST_DEVICE inline Rgb dispersion_mask(int32_t channel) {
  Rgb m(0.f);
  m[channel] = 3.f;
  return m;
}

// Linear interpolation in a table sampled every 5 nm from 360 nm.
TESSERA_HOST_DEVICE inline Float sample_table(const Float* t, int32_t stride, Float lambda) {
  const Float x = glm::clamp((lambda - kLambdaMin) * 0.2f, 0.f, static_cast<Float>(kSpectralSamples - 1));
  const int32_t i = glm::min(static_cast<int32_t>(x), kSpectralSamples - 2);
  const Float f = x - static_cast<Float>(i);
  return (1.f - f) * t[i * stride] + f * t[(i + 1) * stride];
}

// Planck's law relative to its peak, B(lambda, T) / B(lambda_max, T), in
// float for the kernels or double for tables (below 1000 K the visible
// values are far under float's range). 0 for T beyond 1e30 K, where
// lambda T would overflow float (the visible values are ~0 there anyway).
TESSERA_HOST_DEVICE inline float exp_minus_one(float x) { return expm1f(x); }
TESSERA_HOST_DEVICE inline double exp_minus_one(double x) { return ::expm1(x); }

template <class T>
TESSERA_HOST_DEVICE inline T planck_over_peak(T lambda_nm, T kelvin) {
  if (!(kelvin > T(0)) || !(lambda_nm > T(0)) || !(kelvin < T(1e30))) return T(0);
  const T c2 = T(1.4387769e7);  // h c / k_B in nm K
  const T peak = T(2.8977721e6) / kelvin;  // Wien's displacement law, nm
  const T r = peak / lambda_nm;
  return (r * r) * (r * r) * r * exp_minus_one(c2 / (peak * kelvin)) / exp_minus_one(c2 / (lambda_nm * kelvin));
}

TESSERA_HOST_DEVICE inline Float blackbody_relative(Float lambda_nm, Float kelvin) {
  return planck_over_peak<Float>(lambda_nm, kelvin);
}

TESSERA_HOST_DEVICE inline Float sigmoid(Float x) {
  if (glm::isinf(x)) return x > 0.f ? 1.f : 0.f;
  return 0.5f + x / (2.f * glm::sqrt(1.f + x * x));
}

// Sigmoid-polynomial coefficients (c0 lambda^2 + c1 lambda + c2) of the
// smooth reflectance whose colour is rgb, each component in [0, 1]: trilinear
// in the table, indexed by the largest component and the other two relative to it.
// Out of line on the GPU (device.h), like the other spectral-only functions
// the path calls (sample_wavelengths, spectral_to_rgb): RGB scenes never call them.
TESSERA_HOST_DEVICE TESSERA_DEVICE_NOINLINE inline Vec3 rgb_sigmoid_coefficients(const SpectralView& v, Rgb rgb) {
  if (rgb.x == rgb.y && rgb.y == rgb.z) {  // a constant spectrum
    const Float c = rgb.x;
    if (!(c > 0.f)) return Vec3(0.f, 0.f, -INFINITY);
    if (!(c < 1.f)) return Vec3(0.f, 0.f, INFINITY);
    return Vec3(0.f, 0.f, (c - 0.5f) / glm::sqrt(c * (1.f - c)));
  }
  const int32_t maxc = rgb.x > rgb.y ? (rgb.x > rgb.z ? 0 : 2) : (rgb.y > rgb.z ? 1 : 2);
  const Float z = rgb[maxc];
  const int32_t res = v.res;
  const Float x = rgb[(maxc + 1) % 3] * static_cast<Float>(res - 1) / z;
  const Float y = rgb[(maxc + 2) % 3] * static_cast<Float>(res - 1) / z;
  // The last scale entry at or below z (the scale rises from 0 to 1).
  int32_t lo = 0, hi = res - 2;
  while (lo < hi) {
    const int32_t mid = (lo + hi + 1) / 2;
    if (v.table_scale[mid] <= z) lo = mid;
    else hi = mid - 1;
  }
  const int32_t zi = lo;
  const int32_t xi = glm::clamp(static_cast<int32_t>(x), 0, res - 2);
  const int32_t yi = glm::clamp(static_cast<int32_t>(y), 0, res - 2);
  const Float dx = x - static_cast<Float>(xi), dy = y - static_cast<Float>(yi);
  const Float dz = (z - v.table_scale[zi]) / (v.table_scale[zi + 1] - v.table_scale[zi]);
  auto at = [&](int32_t xx, int32_t yy, int32_t zz) {
    const Float* c = v.table + ((((static_cast<size_t>(maxc) * res + zz) * res + yy) * res + xx) * 3);
    return Vec3(c[0], c[1], c[2]);
  };
  auto lerp = [](Float t, Vec3 a, Vec3 b) { return (1.f - t) * a + t * b; };
  return lerp(dz,
              lerp(dy, lerp(dx, at(xi, yi, zi), at(xi + 1, yi, zi)), lerp(dx, at(xi, yi + 1, zi), at(xi + 1, yi + 1, zi))),
              lerp(dy, lerp(dx, at(xi, yi, zi + 1), at(xi + 1, yi, zi + 1)),
                   lerp(dx, at(xi, yi + 1, zi + 1), at(xi + 1, yi + 1, zi + 1))));
}

TESSERA_HOST_DEVICE inline Rgb eval_sigmoid_spectrum(Vec3 c, const Wavelengths& wl) {
  Rgb out;
  for (int i = 0; i < 3; ++i) {
    const Float l = wl.lambda[i];
    out[i] = sigmoid((c.x * l + c.y) * l + c.z);
  }
  return out;
}

// The three doors (see the top of the file). In RGB mode (wl null) the
// identity, except that an albedo is clamped to [0,1] in both modes.
TESSERA_HOST_DEVICE inline Rgb spectral_albedo(const SpectralView& v, const Wavelengths* wl, Rgb rgb) {
  rgb = glm::clamp(rgb, Rgb(0.f), Rgb(1.f));
  if (!wl) return rgb;
  if (!(rgb.x == rgb.x && rgb.y == rgb.y && rgb.z == rgb.z)) return Rgb(0.f);
  return eval_sigmoid_spectrum(rgb_sigmoid_coefficients(v, rgb), *wl);
}

TESSERA_HOST_DEVICE inline Rgb spectral_unbounded(const SpectralView& v, const Wavelengths* wl, Rgb rgb) {
  if (!wl) return rgb;
  const Float m = max_component(rgb);
  if (!(m > 0.f) || !(m < INFINITY)) return m == INFINITY ? Rgb(INFINITY) : Rgb(0.f);
  const Float scale = 2.f * m;
  return scale * eval_sigmoid_spectrum(rgb_sigmoid_coefficients(v, glm::max(rgb / scale, Rgb(0.f))), *wl);
}

TESSERA_HOST_DEVICE inline Rgb spectral_illuminant(const SpectralView& v, const Wavelengths* wl, Rgb rgb) {
  if (!wl) return rgb;
  Rgb s = spectral_unbounded(v, wl, rgb);
  for (int i = 0; i < 3; ++i) s[i] *= sample_table(v.illuminant, 1, wl->lambda[i]);
  return s;
}

// A tabulated spectrum (kSpectralSamples values from 360 nm) at the path's wavelengths.
TESSERA_HOST_DEVICE inline Rgb sample_spectrum(const Float* table, const Wavelengths& wl) {
  return Rgb(sample_table(table, 1, wl.lambda[0]), sample_table(table, 1, wl.lambda[1]),
             sample_table(table, 1, wl.lambda[2]));
}

// Linear sRGB of one sample's radiance at the path's wavelengths (pbrt-v4's
// cie1931 sensor: the Monte Carlo estimate of XYZ, then the colour space's matrix).
TESSERA_HOST_DEVICE TESSERA_DEVICE_NOINLINE inline Rgb spectral_to_rgb(const SpectralView& v, const Wavelengths& wl, Rgb L) {
  Vec3 xyz(0.f);
  for (int i = 0; i < 3; ++i) {
    if (!(wl.pdf[i] > 0.f) || L[i] == 0.f) continue;
    const Float w = L[i] / wl.pdf[i];
    xyz += w * Vec3(sample_table(v.cmf, 3, wl.lambda[i]), sample_table(v.cmf + 1, 3, wl.lambda[i]),
                    sample_table(v.cmf + 2, 3, wl.lambda[i]));
  }
  return v.rgb_from_xyz * (xyz * (v.inv_y_integral / 3.f));
}

}  // namespace tessera
