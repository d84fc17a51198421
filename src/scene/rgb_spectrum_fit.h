// The RGB-to-spectrum fit of Jakob & Hanika (2019), "A Low-Dimensional
// Function Space for Efficient Spectral Upsampling", which pbrt-v4 uses for
// every RGB a scene gives: a reflectance s(lambda) = sigmoid(c0 l^2 + c1 l + c2)
// whose colour under the sRGB illuminant (D65) is the RGB. Our own Gauss-Newton
// solver (no Debian package provides one); the table it fills is generated once
// at build time (tools/gen_rgb_spectrum_table) and embedded in the binary.
//
// Integrals are over 360-830 nm with the CIE tables interpolated linearly, as
// the renderer's spectral film sees them, so an RGB survives the round trip
// RGB -> spectrum -> film -> RGB.
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <vector>

namespace tessera {

using Coeffs3 = std::array<double, 3>;
using Mat3d = std::array<std::array<double, 3>, 3>;

// sRGB primaries with the white of the D65 table, integrated as the film does.
struct SrgbColourSystem {
  Mat3d xyz_from_rgb{}, rgb_from_xyz{};
  std::array<double, 3> white_xyz{};  // Y = 1
  double y_integral = 0.;             // integral of y-bar (nm)
  double d65_luminance_scale = 0.;    // D65 times this has luminance 1
};
const SrgbColourSystem& srgb_colour_system();

// Luminance Y = integral(y-bar s) / integral(y-bar) of a spectrum (lambda in nm).
double spectrum_luminance(const std::function<double(double)>& s);

// Linear sRGB the film records for an emission spectrum s (lambda in nm):
// the inverse of the illuminant door of kernels/spectral.h.
std::array<double, 3> emission_spectrum_rgb(const std::function<double(double)>& s);

// Linear sRGB of the reflectance spectrum with coefficients c (for lambda in
// nm) lit by D65 (white: (1,1,1) for the constant spectrum 1).
std::array<double, 3> sigmoid_spectrum_rgb(const Coeffs3& c_nm);

// Coefficients (for lambda in nm) whose spectrum has colour rgb (components
// in [0,1]), starting the Gauss-Newton iteration from `start` (coefficients for
// lambda normalised to [0,1] over 360-830 nm; updated in place). Returns the
// final residual (CIELAB distance; below 1e-3 where the RGB is reachable).
double fit_sigmoid_coefficients(const std::array<double, 3>& rgb, Coeffs3* start_normalised, Coeffs3* c_nm);

// The lookup table pbrt-v4 uses, at resolution res: res brightness values
// (smoothstep(smoothstep(k / (res - 1)))), then coefficients for
// [max component 0..2][z][y][x][3] (see kernels/spectral.h).
struct RgbSpectrumTable {
  int32_t res = 0;
  std::vector<float> scale;
  std::vector<float> coeffs;
};
RgbSpectrumTable build_rgb_spectrum_table(int32_t res, unsigned threads);

}  // namespace tessera
