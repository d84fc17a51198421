#include "scene/rgb_spectrum_fit.h"

#include <algorithm>
#include <cmath>
#include <thread>

#include "scene/cie_tables.h"

namespace tessera {
namespace {

// Simpson's 3/8 rule on three sub-intervals per 5 nm table interval: exact for
// the product of two piecewise-linear tables, and fine for smooth sigmoids.
constexpr int kFine = (kCieSamples - 1) * 3 + 1;

struct FineGrid {
  double lambda[kFine];
  double weight[kFine];
  double cmf[kFine][3];
  double d65[kFine];
};

const FineGrid& fine_grid() {
  static const FineGrid g = [] {
    FineGrid f{};
    const double h = kCieLambdaStep / 3.0;
    for (int i = 0; i < kFine; ++i) {
      f.lambda[i] = kCieLambdaMin + i * h;
      double w = (i == 0 || i == kFine - 1) ? 1.0 : (i % 3 == 0 ? 2.0 : 3.0);
      f.weight[i] = w * 3.0 * h / 8.0;
      for (int c = 0; c < 3; ++c) f.cmf[i][c] = cie_table_at(&kCie1931Xyz[0][c], 3, f.lambda[i]);
      f.d65[i] = cie_table_at(kCieD65, 1, f.lambda[i]);
    }
    return f;
  }();
  return g;
}

Mat3d inverse(const Mat3d& m) {
  const double det = m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) -
                     m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) +
                     m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
  Mat3d r{};
  r[0][0] = (m[1][1] * m[2][2] - m[1][2] * m[2][1]) / det;
  r[0][1] = (m[0][2] * m[2][1] - m[0][1] * m[2][2]) / det;
  r[0][2] = (m[0][1] * m[1][2] - m[0][2] * m[1][1]) / det;
  r[1][0] = (m[1][2] * m[2][0] - m[1][0] * m[2][2]) / det;
  r[1][1] = (m[0][0] * m[2][2] - m[0][2] * m[2][0]) / det;
  r[1][2] = (m[0][2] * m[1][0] - m[0][0] * m[1][2]) / det;
  r[2][0] = (m[1][0] * m[2][1] - m[1][1] * m[2][0]) / det;
  r[2][1] = (m[0][1] * m[2][0] - m[0][0] * m[2][1]) / det;
  r[2][2] = (m[0][0] * m[1][1] - m[0][1] * m[1][0]) / det;
  return r;
}

std::array<double, 3> mul(const Mat3d& m, const std::array<double, 3>& v) {
  return {m[0][0] * v[0] + m[0][1] * v[1] + m[0][2] * v[2], m[1][0] * v[0] + m[1][1] * v[1] + m[1][2] * v[2],
          m[2][0] * v[0] + m[2][1] * v[1] + m[2][2] * v[2]};
}

double sigmoid(double x) { return 0.5 + x / (2.0 * std::sqrt(1.0 + x * x)); }

// Per fine sample, the RGB contribution of reflectance 1 there under D65.
struct RgbWeights {
  double w[kFine][3];
};
const RgbWeights& rgb_weights() {
  static const RgbWeights r = [] {
    const FineGrid& g = fine_grid();
    const SrgbColourSystem& cs = srgb_colour_system();
    RgbWeights out{};
    for (int i = 0; i < kFine; ++i) {
      const std::array<double, 3> xyz = {g.cmf[i][0], g.cmf[i][1], g.cmf[i][2]};
      const std::array<double, 3> rgb = mul(cs.rgb_from_xyz, xyz);
      const double k = g.d65[i] * g.weight[i] * cs.d65_luminance_scale / cs.y_integral;
      for (int c = 0; c < 3; ++c) out.w[i][c] = rgb[c] * k;
    }
    return out;
  }();
  return r;
}

std::array<double, 3> lab(const std::array<double, 3>& rgb) {
  const SrgbColourSystem& cs = srgb_colour_system();
  const std::array<double, 3> xyz = mul(cs.xyz_from_rgb, rgb);
  auto f = [](double t) {
    constexpr double d = 6.0 / 29.0;
    return t > d * d * d ? std::cbrt(t) : t / (3.0 * d * d) + 4.0 / 29.0;
  };
  const double fx = f(xyz[0] / cs.white_xyz[0]), fy = f(xyz[1] / cs.white_xyz[1]), fz = f(xyz[2] / cs.white_xyz[2]);
  return {116.0 * fy - 16.0, 500.0 * (fx - fy), 200.0 * (fy - fz)};
}

// RGB of the spectrum with coefficients for normalised lambda, and its
// derivatives d rgb / d c (analytic: one pass over the samples).
std::array<double, 3> rgb_and_jacobian(const Coeffs3& c, Mat3d* d_rgb) {
  const FineGrid& g = fine_grid();
  const RgbWeights& w = rgb_weights();
  std::array<double, 3> out{0., 0., 0.};
  *d_rgb = Mat3d{};
  for (int i = 0; i < kFine; ++i) {
    const double x = (g.lambda[i] - kCieLambdaMin) / (kCieLambdaStep * (kCieSamples - 1));
    const double p = (c[0] * x + c[1]) * x + c[2];
    const double q = 1.0 + p * p;
    const double s = 0.5 + p / (2.0 * std::sqrt(q));
    const double ds = 1.0 / (2.0 * q * std::sqrt(q));
    const double dp[3] = {x * x, x, 1.0};
    for (int k = 0; k < 3; ++k) {
      out[k] += w.w[i][k] * s;
      for (int j = 0; j < 3; ++j) (*d_rgb)[k][j] += w.w[i][k] * ds * dp[j];
    }
  }
  return out;
}

Coeffs3 to_nm(const Coeffs3& c) {
  const double c0 = kCieLambdaMin, c1 = 1.0 / (kCieLambdaStep * (kCieSamples - 1));
  return {c[0] * c1 * c1, c[1] * c1 - 2.0 * c[0] * c0 * c1 * c1, c[2] - c[1] * c0 * c1 + c[0] * c0 * c0 * c1 * c1};
}

double smoothstep(double x) { return x * x * (3.0 - 2.0 * x); }

}  // namespace

const SrgbColourSystem& srgb_colour_system() {
  static const SrgbColourSystem cs = [] {
    SrgbColourSystem s;
    const FineGrid& g = fine_grid();
    std::array<double, 3> d65_xyz{0., 0., 0.};
    for (int i = 0; i < kFine; ++i) {
      s.y_integral += g.weight[i] * g.cmf[i][1];
      for (int c = 0; c < 3; ++c) d65_xyz[c] += g.weight[i] * g.cmf[i][c] * g.d65[i];
    }
    // D65 scaled to luminance 1 (Y = integral(y-bar s) / integral(y-bar)).
    s.d65_luminance_scale = s.y_integral / d65_xyz[1];
    for (int c = 0; c < 3; ++c) s.white_xyz[c] = d65_xyz[c] / d65_xyz[1];
    // sRGB primaries (ITU-R BT.709) scaled so that RGB (1,1,1) is the white.
    const double prim[3][2] = {{0.64, 0.33}, {0.30, 0.60}, {0.15, 0.06}};
    Mat3d m{};
    for (int p = 0; p < 3; ++p) {
      const double x = prim[p][0], y = prim[p][1];
      m[0][p] = x / y;
      m[1][p] = 1.0;
      m[2][p] = (1.0 - x - y) / y;
    }
    const std::array<double, 3> k = mul(inverse(m), s.white_xyz);
    for (int r = 0; r < 3; ++r)
      for (int p = 0; p < 3; ++p) s.xyz_from_rgb[r][p] = m[r][p] * k[p];
    s.rgb_from_xyz = inverse(s.xyz_from_rgb);
    return s;
  }();
  return cs;
}

double spectrum_luminance(const std::function<double(double)>& s) {
  const FineGrid& g = fine_grid();
  double y = 0.;
  for (int i = 0; i < kFine; ++i) y += g.weight[i] * g.cmf[i][1] * s(g.lambda[i]);
  return y / srgb_colour_system().y_integral;
}

std::array<double, 3> emission_spectrum_rgb(const std::function<double(double)>& s) {
  const FineGrid& g = fine_grid();
  std::array<double, 3> xyz{0., 0., 0.};
  for (int i = 0; i < kFine; ++i) {
    const double v = g.weight[i] * s(g.lambda[i]);
    for (int c = 0; c < 3; ++c) xyz[c] += g.cmf[i][c] * v;
  }
  const SrgbColourSystem& cs = srgb_colour_system();
  for (double& c : xyz) c /= cs.y_integral;
  return mul(cs.rgb_from_xyz, xyz);
}

std::array<double, 3> sigmoid_spectrum_rgb(const Coeffs3& c_nm) {
  const FineGrid& g = fine_grid();
  const RgbWeights& w = rgb_weights();
  std::array<double, 3> out{0., 0., 0.};
  for (int i = 0; i < kFine; ++i) {
    const double l = g.lambda[i];
    const double x = (c_nm[0] * l + c_nm[1]) * l + c_nm[2];
    const double s = std::isinf(x) ? (x > 0 ? 1.0 : 0.0) : sigmoid(x);
    for (int k = 0; k < 3; ++k) out[k] += w.w[i][k] * s;
  }
  return out;
}

double fit_sigmoid_coefficients(const std::array<double, 3>& rgb, Coeffs3* c, Coeffs3* c_nm) {
  const std::array<double, 3> target = lab(rgb);
  double r_norm = 0.;
  for (int it = 0; it < 30; ++it) {
    Mat3d d_rgb;
    const std::array<double, 3> rgb_c = rgb_and_jacobian(*c, &d_rgb);
    const std::array<double, 3> l = lab(rgb_c);
    const std::array<double, 3> r = {l[0] - target[0], l[1] - target[1], l[2] - target[2]};
    r_norm = std::sqrt(r[0] * r[0] + r[1] * r[1] + r[2] * r[2]);
    if (r_norm < 1e-6) break;
    // J = d lab / d rgb (central differences: lab is cheap) times d rgb / d c.
    Mat3d d_lab{};
    constexpr double eps = 1e-6;
    for (int k = 0; k < 3; ++k) {
      std::array<double, 3> a = rgb_c, b = rgb_c;
      a[k] += eps;
      b[k] -= eps;
      const std::array<double, 3> la = lab(a), lb = lab(b);
      for (int row = 0; row < 3; ++row) d_lab[row][k] = (la[row] - lb[row]) / (2.0 * eps);
    }
    Mat3d J{};
    for (int row = 0; row < 3; ++row)
      for (int col = 0; col < 3; ++col)
        for (int k = 0; k < 3; ++k) J[row][col] += d_lab[row][k] * d_rgb[k][col];
    const double det = J[0][0] * (J[1][1] * J[2][2] - J[1][2] * J[2][1]) -
                       J[0][1] * (J[1][0] * J[2][2] - J[1][2] * J[2][0]) +
                       J[0][2] * (J[1][0] * J[2][1] - J[1][1] * J[2][0]);
    if (!(std::abs(det) > 1e-300)) break;
    const std::array<double, 3> step = mul(inverse(J), r);
    for (int k = 0; k < 3; ++k) (*c)[k] -= step[k];
    // Keep the sigmoid's argument bounded: very saturated colours drive the
    // coefficients to infinity (a box spectrum) without changing the colour much.
    const double m = std::max({std::abs((*c)[0]), std::abs((*c)[1]), std::abs((*c)[2])});
    if (m > 200.0)
      for (int k = 0; k < 3; ++k) (*c)[k] *= 200.0 / m;
  }
  *c_nm = to_nm(*c);
  return r_norm;
}

RgbSpectrumTable build_rgb_spectrum_table(int32_t res, unsigned threads) {
  RgbSpectrumTable t;
  t.res = res;
  t.scale.resize(res);
  for (int k = 0; k < res; ++k) t.scale[k] = float(smoothstep(smoothstep(double(k) / (res - 1))));
  t.coeffs.assign(size_t(3) * res * res * res * 3, 0.f);
  (void)srgb_colour_system();
  (void)rgb_weights();
  // Each (max component, y) row is independent: rows go to threads in turn.
  // Along z the solution of the previous brightness starts the next, from a
  // mid brightness up and then down, as the colours change smoothly.
  auto row = [&](int l, int j) {
    const double y = double(j) / (res - 1);
    for (int i = 0; i < res; ++i) {
      const double x = double(i) / (res - 1);
      auto solve = [&](int k, Coeffs3* c) {
        const double z = t.scale[k];
        std::array<double, 3> rgb{};
        rgb[l] = z;
        rgb[(l + 1) % 3] = x * z;
        rgb[(l + 2) % 3] = y * z;
        Coeffs3 nm;
        fit_sigmoid_coefficients(rgb, c, &nm);
        float* out = &t.coeffs[((((size_t(l) * res + k) * res + j) * res + i) * 3)];
        for (int q = 0; q < 3; ++q) out[q] = float(nm[q]);
      };
      const int start = res / 5;
      Coeffs3 c{0., 0., 0.};
      for (int k = start; k < res; ++k) solve(k, &c);
      c = {0., 0., 0.};
      for (int k = start; k >= 0; --k) solve(k, &c);
    }
  };
  const int rows = 3 * res;
  threads = std::max(1u, threads);
  std::vector<std::thread> pool;
  for (unsigned th = 0; th < threads; ++th)
    pool.emplace_back([&, th] {
      for (int r = int(th); r < rows; r += int(threads)) row(r / res, r % res);
    });
  for (std::thread& p : pool) p.join();
  return t;
}

}  // namespace tessera
