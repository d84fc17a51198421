// Spectral transport's tables: the RGB-to-spectrum fit and its embedded
// table, the wavelength sampling, and the film's return to RGB.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "kernels/spectral.h"
#include "scene/named_spectra.h"
#include "scene/rgb_spectrum_fit.h"
#include "scene/spectral_tables.h"
#include "scene_test_helpers.h"

using namespace tessera;

namespace {


// The film's estimate of a spectrum's linear sRGB (spectrum_at: wavelengths
// -> values), with n stratified wavelength triples.
template <class SpectrumAt>
Rgb film_rgb(const SpectralView& v, SpectrumAt spectrum_at, int n) {
  Vec3 sum(0.f);
  for (int i = 0; i < n; ++i) {
    const Wavelengths wl = sample_wavelengths((static_cast<Float>(i) + 0.5f) / static_cast<Float>(n));
    sum += spectral_to_rgb(v, wl, spectrum_at(wl));
  }
  return sum / static_cast<Float>(n);
}

}  // namespace

TEST(RgbSpectrumFit, ReachableColoursAreReproducedExactly) {
  const std::array<double, 3> colours[] = {{0.5, 0.5, 0.5}, {0.8, 0.2, 0.1}, {0.1, 0.9, 0.3},
                                           {0.05, 0.05, 0.9}, {0.9, 0.9, 0.2}, {0.02, 0.3, 0.6}};
  for (const auto& rgb : colours) {
    Coeffs3 start{0., 0., 0.}, nm;
    EXPECT_LT(fit_sigmoid_coefficients(rgb, &start, &nm), 1e-4);
    const std::array<double, 3> back = sigmoid_spectrum_rgb(nm);
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(back[c], rgb[c], 1e-5) << rgb[0] << " " << rgb[1] << " " << rgb[2];
  }
}

TEST(RgbSpectrumFit, ColourSystemIsSrgbWithD65White) {
  const SrgbColourSystem& cs = srgb_colour_system();
  EXPECT_NEAR(cs.y_integral, 106.857, 0.01);  // CIE: 106.856895
  EXPECT_NEAR(cs.white_xyz[0], 0.9505, 2e-4);
  EXPECT_NEAR(cs.white_xyz[2], 1.0888, 3e-4);
  // The familiar sRGB matrix, up to the white point's rounding.
  EXPECT_NEAR(cs.rgb_from_xyz[0][0], 3.2405, 2e-3);
  EXPECT_NEAR(cs.rgb_from_xyz[1][1], 1.8760, 2e-3);
  EXPECT_NEAR(cs.rgb_from_xyz[2][2], 1.0572, 2e-3);
}

// The embedded table, interpolated as the kernels read it, gives back each
// colour: within 0.3 % of full scale over random colours.
TEST(SpectralTables, EmbeddedTableReproducesColours) {
  const SpectralView v = srgb_spectral_tables().view();
  ASSERT_EQ(v.res, 64);
  std::mt19937 gen(7);
  std::uniform_real_distribution<float> u(0.f, 1.f);
  double worst = 0.;
  for (int i = 0; i < 500; ++i) {
    const Rgb rgb(u(gen), u(gen), u(gen));
    const Vec3 c = rgb_sigmoid_coefficients(v, rgb);
    const std::array<double, 3> back = sigmoid_spectrum_rgb({c.x, c.y, c.z});
    for (int k = 0; k < 3; ++k) worst = std::max(worst, std::abs(back[k] - rgb[k]));
  }
  EXPECT_LT(worst, 3e-3);
  // Greys are constant spectra, black and white included.
  for (float g : {0.f, 0.25f, 1.f}) {
    const Vec3 c = rgb_sigmoid_coefficients(v, Rgb(g));
    Wavelengths wl = sample_wavelengths(0.3f);
    EXPECT_VEC3_NEAR(eval_sigmoid_spectrum(c, wl), Vec3(g), 1e-6f);
  }
}

TEST(SpectralTables, WavelengthSamplingFollowsItsDensity) {
  // The sampling map is the inverse of the density's cdf.
  for (float u : {0.01f, 0.2f, 0.5f, 0.8f, 0.99f}) {
    const Float lambda = sample_visible_wavelength(u);
    double cdf = 0.;
    const int n = 20000;
    const double h = (lambda - kLambdaMin) / n;
    for (int i = 0; i < n; ++i) cdf += visible_wavelength_pdf(static_cast<Float>(kLambdaMin + (i + 0.5) * h)) * h;
    EXPECT_NEAR(cdf, u, 2e-4) << u;
  }
  EXPECT_NEAR(sample_visible_wavelength(0.f), kLambdaMin, 0.01f);
  EXPECT_NEAR(sample_visible_wavelength(1.f), kLambdaMax, 0.5f);
  const Wavelengths wl = sample_wavelengths(0.9f);
  for (int i = 0; i < 3; ++i) EXPECT_GT(wl.pdf[i], 0.f);
}

// What enters as RGB leaves the film as the same RGB: emission seen directly,
// and a reflectance lit by white light.
TEST(SpectralTables, FilmReturnsTheRgbOfIlluminantsAndReflectances) {
  const SpectralView v = srgb_spectral_tables().view();
  const int n = 100000;
  for (Rgb rgb : {Rgb(1.f), Rgb(4.f, 2.f, 0.5f), Rgb(0.2f, 0.7f, 0.1f)}) {
    const Rgb seen = film_rgb(v, [&](const Wavelengths& wl) { return spectral_illuminant(v, &wl, rgb); }, n);
    EXPECT_VEC3_NEAR(seen, rgb, 2e-3f * max_component(rgb));
  }
  for (Rgb a : {Rgb(0.5f), Rgb(0.8f, 0.3f, 0.1f), Rgb(0.1f, 0.2f, 0.9f)}) {
    const Rgb seen = film_rgb(
        v, [&](const Wavelengths& wl) { return spectral_albedo(v, &wl, a) * spectral_illuminant(v, &wl, Rgb(1.f)); }, n);
    EXPECT_VEC3_NEAR(seen, a, 4e-3f);
  }
  // Unbounded spectra scale: twice the RGB, twice the spectrum.
  const Wavelengths wl = sample_wavelengths(0.37f);
  EXPECT_VEC3_NEAR(spectral_unbounded(v, &wl, Rgb(6.f, 2.f, 1.f)), 2.f * spectral_unbounded(v, &wl, Rgb(3.f, 1.f, 0.5f)),
                   1e-5f);
  // RGB mode: every door is the identity, but albedos are clamped to [0,1].
  EXPECT_EQ(spectral_albedo(v, nullptr, Rgb(0.3f, 2.f, -1.f)), Rgb(0.3f, 1.f, 0.f));
  EXPECT_EQ(spectral_unbounded(v, nullptr, Rgb(0.3f, 2.f, 7.f)), Rgb(0.3f, 2.f, 7.f));
  EXPECT_EQ(spectral_illuminant(v, nullptr, Rgb(0.3f, 2.f, 7.f)), Rgb(0.3f, 2.f, 7.f));
}

// Planck's law through the film has the chromaticity of a blackbody.
TEST(SpectralTables, BlackbodyHasItsColour) {
  const SpectralView v = srgb_spectral_tables().view();
  const double y = spectrum_luminance([](double l) { return blackbody_relative(Float(l), 3000.f); });
  const Rgb seen = film_rgb(
      v, [&](const Wavelengths& wl) {
        return Rgb(blackbody_relative(wl.lambda[0], 3000.f), blackbody_relative(wl.lambda[1], 3000.f),
                   blackbody_relative(wl.lambda[2], 3000.f)) / static_cast<Float>(y);
      },
      100000);
  EXPECT_NEAR(luminance(seen), 1.f, 3e-3f);
  EXPECT_VEC3_NEAR(seen, blackbody_rgb(3000.f), 5e-3f);
  // Wien: the peak is where the relative value is 1.
  EXPECT_NEAR(blackbody_relative(2.8977721e6f / 5000.f, 5000.f), 1.f, 1e-5f);
}

// At a dispersive surface the path goes on at one wavelength, picked
// uniformly, with 3 times the throughput: light found afterwards keeps its
// expected colour.
TEST(SpectralTables, DispersionContinuesAtOneWavelengthUnbiased) {
  const SpectralView v = srgb_spectral_tables().view();
  const int n = 90000;
  Vec3 sum(0.f);
  int picked[3] = {0, 0, 0};
  for (int i = 0; i < n; ++i) {
    Wavelengths wl = sample_wavelengths((i + 0.5f) / n);
    const int32_t c = dispersion_channel(wl, static_cast<Float>(i % 3) / 3.f + 0.1f);
    ++picked[c];
    EXPECT_EQ(dispersion_channel(wl, 0.99f), c);  // later dispersive surfaces keep it
    const Rgb L = dispersion_mask(c) * spectral_illuminant(v, &wl, Rgb(0.3f, 0.6f, 0.9f));
    sum += spectral_to_rgb(v, wl, L);
  }
  EXPECT_EQ(picked[0], n / 3);
  EXPECT_EQ(picked[2], n / 3);
  EXPECT_VEC3_NEAR(sum / static_cast<Float>(n), Vec3(0.3f, 0.6f, 0.9f), 5e-3f);
}
