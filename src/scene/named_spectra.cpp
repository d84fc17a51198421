#include "scene/named_spectra.h"

#include <algorithm>
#include <cmath>
#include <map>

#include "kernels/blackbody_table.h"
#include "kernels/spectral.h"
#include "scene/cie_tables.h"
#include "scene/rgb_spectrum_fit.h"

namespace tessera {
namespace {

// The CIE 1931 matching functions at lambda (nm), from the tabulated standard.
Vec3 cie_xyz(double l) {
  Vec3 v;
  for (int c = 0; c < 3; ++c) v[c] = static_cast<Float>(cie_table_at(&kCie1931Xyz[0][c], 3, l));
  return v;
}

Rgb xyz_to_linear_srgb(Vec3 c) {
  return Rgb(3.2404542f * c.x - 1.5371385f * c.y - 0.4985314f * c.z,
             -0.9692660f * c.x + 1.8760108f * c.y + 0.0415560f * c.z,
             0.0556434f * c.x - 0.2040259f * c.y + 1.0572252f * c.z);
}

// XYZ of a spectrum over the visible range (5 nm steps; normalisation is up to the caller).
template <typename SpectrumFn>
Vec3 integrate_xyz(SpectrumFn&& s) {
  Vec3 sum(0.f);
  for (double l = 360.; l <= 830.; l += 5.) sum += cie_xyz(l) * static_cast<Float>(s(l));
  return sum;
}


// Conductor values are the spectra averaged over rough R/G/B bands (about
// 600-700, 500-600, 400-500 nm). Glasses are in glass_sellmeier().
const std::map<std::string, Rgb>& table() {
  static const std::map<std::string, Rgb> t = {
      {"metal-Au-eta", {0.143f, 0.375f, 1.442f}},   {"metal-Au-k", {3.983f, 2.386f, 1.603f}},
      {"metal-Ag-eta", {0.155f, 0.117f, 0.138f}},   {"metal-Ag-k", {4.828f, 3.122f, 2.147f}},
      {"metal-Al-eta", {1.657f, 0.880f, 0.521f}},   {"metal-Al-k", {9.224f, 6.270f, 4.837f}},
      {"metal-Cu-eta", {0.200f, 0.924f, 1.102f}},   {"metal-Cu-k", {3.913f, 2.453f, 2.142f}},
      {"metal-CuZn-eta", {0.444f, 0.527f, 1.094f}}, {"metal-CuZn-k", {3.695f, 2.765f, 1.829f}},
      {"metal-MgO-eta", {1.732f, 1.738f, 1.760f}},  {"metal-MgO-k", {0.f, 0.f, 0.f}},
      {"metal-TiO2-eta", {2.74f, 2.87f, 3.10f}},    {"metal-TiO2-k", {0.f, 0.f, 0.0f}},
  };
  return t;
}

// pbrt-v4's named glasses as Schott's Sellmeier dispersion formulas
// (n^2 = 1 + sum B_i l^2 / (l^2 - C_i), l in micrometres; catalogue data,
// which reproduce each glass's n_d to 1e-5). pbrt-v4's "glass-F5", "-F10"
// and "-F11" are the dense flints SF5, SF10 and SF11.
struct Sellmeier {
  double B[3], C[3];
  double n(double lambda_nm) const {
    const double l2 = lambda_nm * lambda_nm * 1e-6;
    double n2 = 1.0;
    for (int i = 0; i < 3; ++i) n2 += B[i] * l2 / (l2 - C[i]);
    return std::sqrt(n2);
  }
};

const Sellmeier* glass_sellmeier(const std::string& name) {
  static const std::map<std::string, Sellmeier> glasses = {
      {"glass-BK7", {{1.03961212, 0.231792344, 1.01046945}, {0.00600069867, 0.0200179144, 103.560653}}},
      {"glass-BAF10", {{1.5851495, 0.143559385, 1.08521269}, {0.00926681282, 0.0424489805, 105.613573}}},
      {"glass-FK51A", {{0.971247817, 0.216901417, 0.904651666}, {0.00472301995, 0.0153575612, 168.68133}}},
      {"glass-LASF9", {{2.00029547, 0.298926886, 1.80691843}, {0.0121426017, 0.0538736236, 156.530829}}},
      {"glass-F5", {{1.52481889, 0.187085527, 1.42729015}, {0.011254756, 0.0588995392, 129.141675}}},
      {"glass-F10", {{1.62153902, 0.256287842, 1.64447552}, {0.0122241457, 0.0595736775, 147.468793}}},
      {"glass-F11", {{1.73759695, 0.313747346, 1.89878101}, {0.013188707, 0.0623068142, 155.23629}}},
  };
  auto it = glasses.find(name);
  return it == glasses.end() ? nullptr : &it->second;
}

}  // namespace

std::optional<std::vector<Float>> named_spectrum_samples(const std::string& name) {
  const Sellmeier* g = glass_sellmeier(name);
  if (!g) return std::nullopt;
  std::vector<Float> out(kSpectralSamples);
  for (int i = 0; i < kSpectralSamples; ++i) out[i] = static_cast<Float>(g->n(kCieLambdaMin + kCieLambdaStep * i));
  return out;
}

std::optional<Rgb> named_spectrum_rgb(const std::string& name) {
  if (const Sellmeier* g = glass_sellmeier(name)) return Rgb(static_cast<Float>(g->n(550.0)));
  auto it = table().find(name);
  if (it != table().end()) return it->second;
  // Emission spectra: pbrt-v4 normalises them to unit luminance, and their
  // colour casts (A is orange, F-series greenish) are beyond an RGB renderer's
  // white balance anyway: treat them as white.
  if (name.rfind("stdillum-", 0) == 0 || name.rfind("illum-", 0) == 0) return Rgb(1.f);
  return std::nullopt;
}

namespace {

// XYZ of Planck's law at `kelvin` (unnormalised).
Vec3 blackbody_xyz(Float kelvin) {
  const double c = 299792458., h = 6.62606957e-34, kb = 1.3806488e-23;
  return integrate_xyz([&](double lambda_nm) {
    double l = lambda_nm * 1e-9;
    return (2 * h * c * c) / (std::pow(l, 5) * (std::exp((h * c) / (l * kb * kelvin)) - 1));
  });
}

}  // namespace

Rgb blackbody_rgb(Float kelvin) {
  if (!(kelvin > 0.f)) return Rgb(0.f);
  const Vec3 xyz = blackbody_xyz(kelvin);
  if (!(xyz.y > 0.f)) return Rgb(0.f);
  return glm::max(xyz_to_linear_srgb(xyz / xyz.y), Rgb(0.f));
}

std::vector<Float> build_blackbody_rgb_table() {
  std::vector<Float> t(4 * kBlackbodyTableSize);
  for (int32_t i = 0; i < kBlackbodyTableSize; ++i) {
    const double kelvin = blackbody_table_kelvin(i);
    const std::array<double, 3> rgb = emission_spectrum_rgb([&](double l) { return planck_over_peak(l, kelvin); });
    // Luminance as the film has it; colours outside sRGB (deep red, at low T) clamp at 0 as blackbody_rgb's do.
    const double y = 0.2126 * rgb[0] + 0.7152 * rgb[1] + 0.0722 * rgb[2];
    Float* e = t.data() + 4 * i;
    e[0] = y > 0. ? static_cast<Float>(std::log(y)) : -700.f;
    for (int c = 0; c < 3; ++c) e[1 + c] = y > 0. ? static_cast<Float>(std::max(0., rgb[c]) / y) : 0.f;
  }
  return t;
}

Vec2 blackbody_xy(Float kelvin) {
  const Vec3 xyz = kelvin > 0.f ? blackbody_xyz(kelvin) : Vec3(0.f);
  const Float sum = xyz.x + xyz.y + xyz.z;
  return sum > 0.f ? Vec2(xyz.x / sum, xyz.y / sum) : Vec2(1.f / 3.f);
}

namespace {

// Piecewise-linear value of (wavelength, value) pairs, constant beyond the ends.
double value_at(const std::vector<Float>& pairs, double l) {
  const size_t n = pairs.size() / 2;
  if (l <= pairs[0]) return pairs[1];
  for (size_t i = 0; i + 1 < n; ++i) {
    double l0 = pairs[2 * i], l1 = pairs[2 * i + 2];
    if (l <= l1) {
      double t = l1 > l0 ? (l - l0) / (l1 - l0) : 0.;
      return pairs[2 * i + 1] * (1 - t) + pairs[2 * i + 3] * t;
    }
  }
  return pairs[2 * n - 1];
}

// RGB of a spectrum given as a function, relative to an equal-energy white.
template <typename SpectrumFn>
Rgb spectrum_rgb(SpectrumFn&& f) {
  const Rgb white = xyz_to_linear_srgb(integrate_xyz([](double) { return 1.; }));
  return glm::max(xyz_to_linear_srgb(integrate_xyz(f)) / white, Rgb(0.f));
}

}  // namespace

std::vector<Float> resample_spectrum(const std::vector<Float>& pairs) {
  std::vector<Float> out(kSpectralSamples, 0.f);
  if (pairs.size() < 2) return out;
  for (int i = 0; i < kSpectralSamples; ++i)
    out[i] = static_cast<Float>(value_at(pairs, kCieLambdaMin + kCieLambdaStep * i));
  return out;
}

Rgb sampled_spectrum_rgb(const std::vector<Float>& pairs) {
  if (pairs.size() < 2) return Rgb(0.f);
  return spectrum_rgb([&](double l) { return value_at(pairs, l); });
}

void sampled_conductor_rgb(const std::vector<Float>& eta_pairs, const std::vector<Float>& k_pairs, Float outside_eta,
                           Rgb* eta, Rgb* k) {
  *eta = sampled_spectrum_rgb(eta_pairs);
  *k = sampled_spectrum_rgb(k_pairs);
  if (eta_pairs.size() < 2 || k_pairs.size() < 2 || !(outside_eta > 0.f)) return;
  const double o = outside_eta;
  const Rgb r0 = spectrum_rgb([&](double l) {
    const double n = value_at(eta_pairs, l) / o, kk = value_at(k_pairs, l) / o;
    return ((n - 1) * (n - 1) + kk * kk) / ((n + 1) * (n + 1) + kk * kk);
  });
  for (int c = 0; c < 3; ++c) {
    const double n = (*eta)[c] / o, r = std::min<double>(r0[c], 0.9999);
    const double k2 = (r * (n + 1) * (n + 1) - (n - 1) * (n - 1)) / (1 - r);
    if (k2 >= 0) (*k)[c] = static_cast<Float>(std::sqrt(k2) * o);
  }
}

}  // namespace tessera
