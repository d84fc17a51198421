// Fresnel equations (pbrt-v4 util/scattering.h semantics).
// Header-only, device-safe.
#pragma once

#include "vecmath.h"

namespace tessera {

// Minimal complex number for FrComplex (no std::complex on the device).
struct Complexf {
  Float re = 0.f, im = 0.f;
  TESSERA_HOST_DEVICE Complexf() {}
  TESSERA_HOST_DEVICE Complexf(Float r, Float i = 0.f) : re(r), im(i) {}
};
TESSERA_HOST_DEVICE inline Complexf operator+(Complexf a, Complexf b) { return Complexf(a.re + b.re, a.im + b.im); }
TESSERA_HOST_DEVICE inline Complexf operator-(Complexf a, Complexf b) { return Complexf(a.re - b.re, a.im - b.im); }
TESSERA_HOST_DEVICE inline Complexf operator*(Complexf a, Complexf b) {
  return Complexf(a.re * b.re - a.im * b.im, a.re * b.im + a.im * b.re);
}
TESSERA_HOST_DEVICE inline Float complex_norm(Complexf a) { return a.re * a.re + a.im * a.im; }
// Division; *ok is cleared when the divisor is zero (result then 0).
TESSERA_HOST_DEVICE inline Complexf complex_div(Complexf a, Complexf b, bool* ok) {
  Float n = complex_norm(b);
  if (!(n > 0.f)) {
    *ok = false;
    return Complexf(0.f, 0.f);
  }
  Float s = 1.f / n;
  return Complexf((a.re * b.re + a.im * b.im) * s, (a.im * b.re - a.re * b.im) * s);
}
// Principal square root (pbrt-v4 pstd::sqrt).
TESSERA_HOST_DEVICE inline Complexf complex_sqrt(Complexf z) {
  Float n = glm::sqrt(complex_norm(z));
  if (n == 0.f) return Complexf(0.f, 0.f);
  Float t1 = glm::sqrt(0.5f * (n + fabsf(z.re)));
  Float t2 = 0.5f * z.im / t1;
  if (z.re >= 0.f) return Complexf(t1, t2);
  return Complexf(fabsf(t2), z.im >= 0.f ? t1 : -t1);
}

// Unpolarised Fresnel reflectance of a dielectric interface; eta = n_t / n_i
// for light arriving from the side cos_i > 0 points to. Flips for cos_i < 0.
TESSERA_HOST_DEVICE inline Float fr_dielectric(Float cos_i, Float eta) {
  cos_i = glm::clamp(cos_i, -1.f, 1.f);
  if (cos_i < 0.f) {
    eta = 1.f / eta;
    cos_i = -cos_i;
  }
  Float sin2_i = 1.f - cos_i * cos_i;
  Float sin2_t = sin2_i / (eta * eta);
  if (!(sin2_t < 1.f)) return 1.f;  // total internal reflection (and NaN guard)
  Float cos_t = safe_sqrt(1.f - sin2_t);
  Float d_parl = eta * cos_i + cos_t, d_perp = cos_i + eta * cos_t;
  if (!(d_parl > 0.f) || !(d_perp > 0.f)) return 1.f;  // grazing with eta == 1
  Float r_parl = (eta * cos_i - cos_t) / d_parl;
  Float r_perp = (cos_i - eta * cos_t) / d_perp;
  return glm::clamp(0.5f * (r_parl * r_parl + r_perp * r_perp), 0.f, 1.f);
}

// Fresnel reflectance of a conductor with complex IOR eta + i k (pbrt-v4 FrComplex).
TESSERA_HOST_DEVICE inline Float fr_complex(Float cos_i, Complexf eta) {
  cos_i = glm::clamp(cos_i, 0.f, 1.f);
  Float sin2_i = 1.f - cos_i * cos_i;
  bool ok = true;
  Complexf sin2_t = complex_div(Complexf(sin2_i), eta * eta, &ok);
  if (!ok) return 1.f;  // eta == 0: perfect mirror limit
  Complexf cos_t = complex_sqrt(Complexf(1.f) - sin2_t);
  Complexf ci(cos_i);
  Complexf r_parl = complex_div(eta * ci - cos_t, eta * ci + cos_t, &ok);
  Complexf r_perp = complex_div(ci - eta * cos_t, ci + eta * cos_t, &ok);
  if (!ok) return 1.f;
  Float r = 0.5f * (complex_norm(r_parl) + complex_norm(r_perp));
  if (!(r >= 0.f)) return 1.f;  // NaN guard (overflowing k)
  return glm::min(r, 1.f);
}

TESSERA_HOST_DEVICE inline Rgb fr_complex(Float cos_i, const Rgb& eta, const Rgb& k) {
  return Rgb(fr_complex(cos_i, Complexf(eta.x, k.x)), fr_complex(cos_i, Complexf(eta.y, k.y)),
             fr_complex(cos_i, Complexf(eta.z, k.z)));
}

}  // namespace tessera
