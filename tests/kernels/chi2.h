// The chi-square distribution's tail, for the goodness-of-fit tests of
// sampling routines (bsdf_test.cpp, hair_test.cpp).
#pragma once

#include <cmath>

namespace tessera::chi2 {

// Regularised lower incomplete gamma P(a, x) (Numerical Recipes gser/gcf).
inline double gamma_p(double a, double x) {
  if (x <= 0.0) return 0.0;
  double gln = std::lgamma(a);
  if (x < a + 1.0) {
    double ap = a, sum = 1.0 / a, del = sum;
    for (int n = 0; n < 100000; ++n) {
      ap += 1.0;
      del *= x / ap;
      sum += del;
      if (std::abs(del) < std::abs(sum) * 1e-15) break;
    }
    return sum * std::exp(-x + a * std::log(x) - gln);
  }
  double b = x + 1.0 - a, c = 1.0 / 1e-300, d = 1.0 / b, h = d;
  for (int i = 1; i < 100000; ++i) {
    double an = -i * (i - a);
    b += 2.0;
    d = an * d + b;
    if (std::abs(d) < 1e-300) d = 1e-300;
    c = b + an / c;
    if (std::abs(c) < 1e-300) c = 1e-300;
    d = 1.0 / d;
    double del = d * c;
    h *= del;
    if (std::abs(del - 1.0) < 1e-15) break;
  }
  return 1.0 - std::exp(-x + a * std::log(x) - gln) * h;
}
inline double chi2_survival(double chsq, int dof) { return 1.0 - gamma_p(0.5 * dof, 0.5 * chsq); }

}  // namespace tessera::chi2
