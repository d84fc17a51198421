// RGB stand-ins for pbrt-v4's spectral inputs. Tessera renders in linear sRGB,
// so every spectrum a scene names or lists is reduced to one RGB triple here.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "kernels/spectral.h"

namespace tessera {

// pbrt-v4's built-in named spectra ("metal-Au-eta", "glass-BK7", "stdillum-D65"...)
// as linear sRGB. Glasses give their index at 550 nm in all three channels;
// standard illuminants give (1,1,1) because pbrt-v4 normalises emission spectra
// to unit luminance. nullopt for an unknown name.
std::optional<Rgb> named_spectrum_rgb(const std::string& name);

// Blackbody emission at `kelvin`, scaled to luminance 1 (pbrt-v4 normalises
// blackbody emitters photometrically, so only the colour matters).
Rgb blackbody_rgb(Float kelvin);

// A named spectrum sampled at the spectral tables' wavelengths, for those
// known as spectra (the glasses' dispersion); nullopt for others.
std::optional<std::vector<Float>> named_spectrum_samples(const std::string& name);

// The table kernels/blackbody_table.h reads: the film's RGB of
// B(lambda, T) / B(lambda_max, T) over its temperatures.
std::vector<Float> build_blackbody_rgb_table();

// Chromaticity (CIE 1931 x, y) of a blackbody at `kelvin`.
Vec2 blackbody_xy(Float kelvin);

// A piecewise-linear spectrum given as (wavelength nm, value) pairs, reduced to
// RGB such that a constant spectrum c gives (c, c, c). A rough approximation.
Rgb sampled_spectrum_rgb(const std::vector<Float>& lambda_value_pairs);

// A piecewise-linear spectrum given as (wavelength nm, value) pairs, sampled
// at the spectral tables' wavelengths (kernels/spectral.h), constant beyond its ends.
std::vector<Float> resample_spectrum(const std::vector<Float>& lambda_value_pairs);

// A conductor given by sampled eta and k spectra, as RGB: eta is each
// channel's weighted mean (as sampled_spectrum_rgb) and k is chosen so that
// the channel's normal-incidence reflectance, seen from a medium of index
// `outside_eta` (a coat's), is that of the spectral Fresnel reflectance
// ((n-1)^2 + k^2) / ((n+1)^2 + k^2) (n, k relative to it) reduced to RGB.
// Averaging eta and k separately instead misses the colour of gold by a few per cent.
void sampled_conductor_rgb(const std::vector<Float>& eta_pairs, const std::vector<Float>& k_pairs, Float outside_eta,
                           Rgb* eta, Rgb* k);

}  // namespace tessera
