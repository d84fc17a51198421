// pbrt-v4's hair BSDF (HairBxDF): the Marschner-style R / TT / TRT lobes with
// d'Eon et al. 2011's longitudinal Mp and energy-conserving residual term, and
// the roughness remappings, logistic azimuthal lobes and melanin/colour
// parameterisations of Chiang, Bitterli, Tappan and Burley 2016.
//
// Frame. The local frame is ours, not pbrt's: x = the fiber's tangent
// (increasing curve parameter), z = the OUTWARD normal of the round fiber at
// the hit (our curves are tessellated round tubes, so the shading normal is
// the cylinder's true normal), y = cross(z, x). pbrt-v4 shades a flat ribbon
// facing the ray and reads the offset across the fiber from the ribbon's v
// (h = -1 + 2v). On a round fiber that offset is not a parameter: it follows
// from wo, h = wo.y / |(wo.y, wo.z)| (hair_offset). Derivation: pbrt's frame
// is z_p = the ribbon normal pointing along the ray (away from the viewer),
// y_p = cross(z_p, x), and h > 0 on the +y_p side; the outward normal at
// offset h is n = h y_p - sqrt(1 - h^2) z_p, so y = cross(n, x) =
// -sqrt(1 - h^2) y_p - h z_p, and the viewer's direction -z_p has
// (y, z) components (h, sqrt(1 - h^2)). Azimuths are phi = atan2(w.z, w.y);
// our frame is a rotation of pbrt's about x, so the differences phi_i - phi_o
// that the model reads are pbrt's.
//
// pbrt-v4's sign of h is kept so that fibers shade as pbrt's do, though it is
// the mirror image of the geometry: its R lobe is centred on phi_o - 2 gamma_o
// (gamma_o = asin h), while the mirror reflection of wo about the true normal
// is (-wo.x, -wo.y, wo.z), at phi_o + 2 gamma_o. So for |h| > 1/2 the R lobe
// points into the tube (wi.z < 0), as TT and TRT do by design; most samples
// do. The integrator must let such rays leave through the fiber rather than
// stop at its inside (one-way tube faces).
//
// Why ours: pbrt-v4's HairBxDF is a class over SampledSpectrum with h fixed
// at construction; here it is free functions over RGB that nvcc compiles, h
// comes from wo, and every division, sqrt and asin is guarded so that no input
// (NaN, infinite, zero-length, grazing) gives a non-finite output. Deliberate
// differences from pbrt-v4 are marked "pbrt-v4 differs" below.
//
// Conventions as in bsdf.h: wo and wi point away from the fiber, pdfs are per
// unit solid angle, and hair_f is divided by |wi.z| (as pbrt-v4 does) so that
// the integrator's f * |cos theta_i| leaves the model's sum of lobes.
#pragma once

#include "fresnel.h"

namespace tessera {

// A hair BSDF's parameters with every texture already evaluated.
struct HairFiber {
  Rgb sigma_a{0.f};     // absorption coefficient inside the fiber, per unit radius (pbrt-v4's "sigma_a")
  Float eta = 1.55f;    // fiber index of refraction
  Float beta_m = 0.3f;  // longitudinal roughness in [0,1] (kept in [0.01, 1]: below 0.01 the lobes' variances underflow)
  Float beta_n = 0.3f;  // azimuthal roughness in [0,1] (likewise)
  Float alpha = 2.f;    // cuticle scale tilt, degrees
};

// The offset h in [-1,1] across the fiber at which a ray towards -wo hit it
// (pbrt-v4's h = -1 + 2v), from wo in the frame above; 0 for wo along the fiber.
TESSERA_HOST_DEVICE inline Float hair_offset(const Vec3& wo);

// BSDF value, divided by |wi.z| where that is > 0 (pbrt-v4). 0 for
// non-finite or zero-length directions.
TESSERA_HOST_DEVICE inline Rgb hair_f(const HairFiber& fiber, const Vec3& wo, const Vec3& wi);
// Solid-angle density with which hair_sample produces wi.
TESSERA_HOST_DEVICE inline Float hair_pdf(const HairFiber& fiber, const Vec3& wo, const Vec3& wi);
// hair_f and hair_pdf at once (they share every transcendental). It and
// hair_sample are out of line on the GPU (device.h): hair is rare and large.
TESSERA_HOST_DEVICE inline Rgb hair_f_pdf(const HairFiber& fiber, const Vec3& wo, const Vec3& wi, Float* pdf);
// Picks a lobe (R, TT, TRT, residual) with uc in proportion to the channel
// averages of the Ap terms, theta_i from that lobe's Mp (u) and phi_i from
// its Np (uc's remainder; uniform for the residual). *f and *pdf are
// hair_f and the full mixture's hair_pdf at *wi. False when the pdf is 0 or
// not finite, or wi.z == 0 (where f * |cos| would be 0 anyway).
TESSERA_HOST_DEVICE inline bool hair_sample(const HairFiber& fiber, const Vec3& wo, Float uc, Vec2 u, Vec3* wi, Rgb* f,
                                            Float* pdf);

// pbrt-v4's absorption of the eumelanin and pheomelanin concentrations (d'Eon et al. 2011).
TESSERA_HOST_DEVICE inline Rgb hair_sigma_a_from_concentration(Float eumelanin, Float pheomelanin);
// pbrt-v4's SigmaAFromReflectance: Chiang et al. 2016's fit of the absorption
// that gives a fiber assembly of azimuthal roughness beta_n the colour c
// (clamped to [0,1]; 0 gives the largest float).
TESSERA_HOST_DEVICE inline Rgb hair_sigma_a_from_reflectance(const Rgb& c, Float beta_n);

// ============================================================================

namespace hair_detail {

constexpr int kPMax = 3;  // R, TT, TRT as lobes; kPMax is the residual of all longer paths
constexpr Float k2Pi = 2.f * kPi;

TESSERA_HOST_DEVICE inline bool finite(Float x) { return fabsf(x) <= 3.4e38f; }
// x clamped to [lo, hi]; NaN gives lo.
TESSERA_HOST_DEVICE inline Float clamp_nan(Float x, Float lo, Float hi) { return x > lo ? (x < hi ? x : hi) : lo; }
TESSERA_HOST_DEVICE inline Float average(const Rgb& c) { return (c.x + c.y + c.z) * (1.f / 3.f); }

// w / |w|; false when w is zero-length or not finite. A w already of unit
// length to float precision is kept as it is, so that hair_f and hair_pdf at a
// wi that hair_sample produced reproduce its f and pdf bit for bit.
TESSERA_HOST_DEVICE inline bool unit(const Vec3& w, Vec3* out) {
  if (!is_finite(w)) return false;
  const Float len2 = w.x * w.x + w.y * w.y + w.z * w.z;
  if (!(len2 > 0.f) || !finite(len2)) return false;
  *out = fabsf(len2 - 1.f) <= 1e-6f ? w : w * (1.f / sqrtf(len2));
  return true;
}

// log(I0(x)) - x for x >= 0 (I0: modified Bessel function of the first kind,
// order 0). The subtraction of x is folded in so that Mp's exponent below
// needs no cancellation of terms ~1/v. pbrt-v4 differs: its power series
// stops after 10 terms (2 % low near x = 12) and its large-x form has 1/(16x)
// where the expansion has 1/(8x); here the series runs until it has
// converged and the asymptotic form keeps five terms, so Mp is the exact
// density of the Mp sampling below to float precision.
TESSERA_HOST_DEVICE inline Float log_i0_minus_x(Float x) {
  if (x > 12.f) {
    const Float r = 1.f / x;
    // 1 + sum_k ((2k-1)!!)^2 / (k! (8x)^k), five terms: within 2e-7 for x > 12.
    const Float series = r * (0.125f + r * (0.0703125f + r * (0.0732421875f + r * (0.112152100f + r * 0.227108002f))));
    return -0.5f * logf(k2Pi * x) + log1pf(series);
  }
  const Float q = 0.25f * x * x;  // I0(x) = sum_k q^k / (k!)^2
  Float term = 1.f, sum = 1.f;
  for (int k = 1; k < 30; ++k) {
    term *= q / Float(k * k);
    sum += term;
    if (term < 1e-8f * sum) break;
  }
  return logf(sum) - x;
}

// Longitudinal scattering Mp (d'Eon et al. 2011): the theta marginal of a von
// Mises-Fisher lobe of variance v around (sin, cos) = (-sin_o, cos_o),
// normalised as the integral of Mp cos(theta_i) dtheta_i = 1. cos_i, cos_o >= 0.
TESSERA_HOST_DEVICE inline Float longitudinal(Float sin_i, Float cos_i, Float sin_o, Float cos_o, Float v) {
  const Float a = cos_i * cos_o / v;
  if (v <= 0.1f) {
    // exp(log I0(a) - b - 1/v) / v with b = sin_i sin_o / v (pbrt-v4's log
    // form; its ln 2 + log(1/(2v)) is -log v). a - b - 1/v is -q with q
    // = |(cos_i, sin_i) - (cos_o, -sin_o)|^2 / (2v): free of cancellation.
    const Float q = (sqr(cos_i - cos_o) + sqr(sin_i + sin_o)) / (2.f * v);
    return expf(log_i0_minus_x(a) - q) / v;
  }
  const Float b = sin_i * sin_o / v;
  return expf(log_i0_minus_x(a) + a - b) / (2.f * v * sinhf(1.f / v));
}

// Logistic density of scale s (symmetric about 0) and its trimmed form on
// [-pi, pi]: divided by cdf(pi) - cdf(-pi) = tanh(pi / (2s)).
TESSERA_HOST_DEVICE inline Float trimmed_logistic(Float x, Float s) {
  const Float e = expf(-fabsf(x) / s);
  return e / (s * sqr(1.f + e) * tanhf(kPi / (2.f * s)));
}
TESSERA_HOST_DEVICE inline Float logistic_cdf(Float x, Float s) { return 1.f / (1.f + expf(-x / s)); }
// Inverse-cdf sample of the trimmed logistic on [-pi, pi].
TESSERA_HOST_DEVICE inline Float sample_trimmed_logistic(Float u, Float s) {
  const Float lo = logistic_cdf(-kPi, s), hi = logistic_cdf(kPi, s);
  const Float p = lo + u * (hi - lo);
  const Float x = -s * logf(1.f / p - 1.f);  // +-inf at p = 0 or 1: clamped
  return clamp_nan(x, -kPi, kPi);
}

// Azimuthal deflection of lobe p for the entry angle gamma_o and refracted
// angle gamma_t (Marschner et al. 2003): Phi = 2 p gamma_t - 2 gamma_o + p pi.
TESSERA_HOST_DEVICE inline Float lobe_azimuth(int p, Float gamma_o, Float gamma_t) {
  return 2.f * Float(p) * gamma_t - 2.f * gamma_o + Float(p) * kPi;
}
// x wrapped into [-pi, pi) (x finite).
TESSERA_HOST_DEVICE inline Float wrap_pi(Float x) { return x - k2Pi * floorf((x + kPi) * (1.f / k2Pi)); }

// h = sin gamma_o and cos gamma_o of the offset at which wo sees the fiber,
// from the direction of (wo.y, wo.z): cos gamma_o read off directly rather
// than as sqrt(1 - h^2), which loses it to rounding at grazing angles. Both 0
// and 1 for a wo along the fiber (or not finite).
TESSERA_HOST_DEVICE inline void offset(const Vec3& wo, Float* h, Float* cos_gamma_o) {
  *h = 0.f;
  *cos_gamma_o = 1.f;
  if (!finite(wo.y) || !finite(wo.z)) return;
  // Scaled by the larger component so that the squares neither underflow nor overflow.
  const Float m = fmaxf(fabsf(wo.y), fabsf(wo.z));
  if (!(m > 0.f)) return;
  const Float y = wo.y / m, z = fabsf(wo.z) / m, inv_r = 1.f / sqrtf(y * y + z * z);
  *h = clamp_nan(y * inv_r, -1.f, 1.f);
  *cos_gamma_o = clamp_nan(z * inv_r, 0.f, 1.f);
}

// Everything that depends on the fiber and wo alone.
struct Outgoing {
  Float sin_o[kPMax + 1];  // sin theta_o, rotated by each lobe's scale tilt
  Float cos_o[kPMax + 1];  // cos theta_o likewise, signed (the sampler's); Mp takes |.|
  Float v[kPMax + 1];      // Mp variances
  Float s;                 // Np logistic scale
  Float phi_o, gamma_o, gamma_t;
  Rgb ap[kPMax + 1];       // attenuations A_p
  Float ap_pdf[kPMax + 1]; // lobe choice probabilities: average(A_p) / sum
};

// Fills *t for wo (need not be unit); false for a wo that is not finite or
// zero-length, or a fiber that scatters nothing (all A_p zero).
TESSERA_HOST_DEVICE inline bool outgoing_terms(const HairFiber& fiber, const Vec3& wo_in, Outgoing* t) {
  Vec3 wo;
  if (!unit(wo_in, &wo)) return false;
  const Float eta = (fiber.eta > 0.f && finite(fiber.eta)) ? fiber.eta : 1.55f;
  const Float bm = clamp_nan(fiber.beta_m, 0.01f, 1.f);  // pbrt-v4's HairMaterial clamps likewise
  const Float bn = clamp_nan(fiber.beta_n, 0.01f, 1.f);
  const Float alpha = finite(fiber.alpha) ? fiber.alpha : 0.f;

  // Roughness remappings (Chiang et al. 2016, pbrt-v4): Mp variances per
  // lobe and the logistic scale.
  const Float bm2 = bm * bm, bm4 = bm2 * bm2, bm16 = sqr(sqr(bm4)), bm20 = bm16 * bm4;
  t->v[0] = sqr(0.726f * bm + 0.812f * bm2 + 3.7f * bm20);
  t->v[1] = 0.25f * t->v[0];
  t->v[2] = 4.f * t->v[0];
  t->v[3] = t->v[2];
  const Float bn2 = bn * bn, bn4 = bn2 * bn2, bn16 = sqr(sqr(bn4)), bn22 = bn16 * bn4 * bn2;
  t->s = 0.626657069f * (0.265f * bn + 1.194f * bn2 + 5.372f * bn22);  // sqrt(pi/8) * ...

  // Scale tilt: sin/cos of 2^k alpha by double angles from alpha (pbrt-v4).
  Float sin2k[3], cos2k[3];
  sin2k[0] = sinf(alpha * (kPi / 180.f));
  cos2k[0] = safe_sqrt(1.f - sqr(sin2k[0]));
  for (int k = 1; k < 3; ++k) {
    sin2k[k] = 2.f * cos2k[k - 1] * sin2k[k - 1];
    cos2k[k] = sqr(cos2k[k - 1]) - sqr(sin2k[k - 1]);
  }

  const Float sin_o = clamp_nan(wo.x, -1.f, 1.f), cos_o = safe_sqrt(1.f - sin_o * sin_o);
  // R tilts theta_o by -2 alpha, TT by +alpha, TRT by +4 alpha; the residual not at all.
  t->sin_o[0] = sin_o * cos2k[1] - cos_o * sin2k[1];
  t->cos_o[0] = cos_o * cos2k[1] + sin_o * sin2k[1];
  t->sin_o[1] = sin_o * cos2k[0] + cos_o * sin2k[0];
  t->cos_o[1] = cos_o * cos2k[0] - sin_o * sin2k[0];
  t->sin_o[2] = sin_o * cos2k[2] + cos_o * sin2k[2];
  t->cos_o[2] = cos_o * cos2k[2] - sin_o * sin2k[2];
  t->sin_o[3] = sin_o;
  t->cos_o[3] = cos_o;

  t->phi_o = atan2f(wo.z, wo.y);
  Float h, cos_gamma_o;
  offset(wo, &h, &cos_gamma_o);
  t->gamma_o = atan2f(h, cos_gamma_o);
  // Refraction in the normal plane uses Bravais' modified index (pbrt-v4):
  // etap = sqrt(eta^2 - sin^2 theta_o) / cos theta_o, +inf along the fiber.
  const Float etap = cos_o > 0.f ? safe_sqrt(eta * eta - sin_o * sin_o) / cos_o : kInfinity;
  const Float sin_gt = etap > 0.f ? clamp_nan(h / etap, -1.f, 1.f) : 0.f;
  const Float cos_gt = safe_sqrt(1.f - sin_gt * sin_gt);
  t->gamma_t = asinf(sin_gt);
  const Float sin_t = sin_o / eta, cos_t = safe_sqrt(1.f - sin_t * sin_t);

  // One crossing of the fiber: path length 2 cos gamma_t / cos theta_t.
  const Float path = cos_t > 0.f ? 2.f * cos_gt / cos_t : kInfinity;
  Rgb T;
  for (int c = 0; c < 3; ++c) {
    const Float sa = clamp_nan(fiber.sigma_a[c], 0.f, kInfinity);  // NaN and negative: 0
    T[c] = expf(-(sa * path));                                      // sa * path: 0 or +inf at worst
  }

  // Attenuations: Fresnel at the entry, then (1-F)^2 T for TT, one more
  // internal reflection per order, and the geometric series of the rest.
  const Float F = fr_dielectric(cos_o * cos_gamma_o, eta);
  t->ap[0] = Rgb(F);
  t->ap[1] = sqr(1.f - F) * T;
  t->ap[2] = t->ap[1] * T * F;
  for (int c = 0; c < 3; ++c) {
    const Float tf = T[c] * F, denom = 1.f - tf;
    t->ap[3][c] = denom > 0.f ? t->ap[2][c] * tf / denom : 0.f;  // pbrt-v4 divides unguarded
  }

  Float sum = 0.f;
  for (int p = 0; p <= kPMax; ++p) sum += average(t->ap[p]);
  if (!(sum > 0.f) || !finite(sum)) return false;
  for (int p = 0; p <= kPMax; ++p) t->ap_pdf[p] = average(t->ap[p]) / sum;
  return true;
}

// Sum of the lobes at a unit wi: *f_cos = f * |wi.z| (before pbrt's division
// by |wi.z|), *pdf = the lobe mixture's density.
TESSERA_HOST_DEVICE inline void lobe_sum(const Outgoing& t, const Vec3& wi, Rgb* f_cos, Float* pdf) {
  const Float sin_i = clamp_nan(wi.x, -1.f, 1.f), cos_i = safe_sqrt(1.f - sin_i * sin_i);
  const Float phi = atan2f(wi.z, wi.y) - t.phi_o;
  Rgb fsum(0.f);
  Float psum = 0.f;
  for (int p = 0; p < kPMax; ++p) {
    const Float mp = longitudinal(sin_i, cos_i, t.sin_o[p], fabsf(t.cos_o[p]), t.v[p]);
    const Float np = trimmed_logistic(wrap_pi(phi - lobe_azimuth(p, t.gamma_o, t.gamma_t)), t.s);
    fsum += (mp * np) * t.ap[p];
    psum += mp * np * t.ap_pdf[p];
  }
  const Float mp = longitudinal(sin_i, cos_i, t.sin_o[kPMax], t.cos_o[kPMax], t.v[kPMax]) * kInv2Pi;
  fsum += mp * t.ap[kPMax];
  psum += mp * t.ap_pdf[kPMax];
  *f_cos = fsum;
  *pdf = psum;
}

// f (divided by |wi.z| where > 0) and pdf at a unit wi; finite or zero.
TESSERA_HOST_DEVICE inline Rgb eval(const Outgoing& t, const Vec3& wi, Float* pdf) {
  Rgb f;
  lobe_sum(t, wi, &f, pdf);
  const Float c = fabsf(wi.z);
  if (c > 0.f) f /= c;
  if (!is_finite(f)) f = Rgb(0.f);
  if (!finite(*pdf)) *pdf = 0.f;
  return f;
}

}  // namespace hair_detail

TESSERA_HOST_DEVICE inline Float hair_offset(const Vec3& wo) {
  Float h, cos_gamma_o;
  hair_detail::offset(wo, &h, &cos_gamma_o);
  return h;
}

TESSERA_HOST_DEVICE TESSERA_DEVICE_NOINLINE inline Rgb hair_f_pdf(const HairFiber& fiber, const Vec3& wo, const Vec3& wi,
                                                                  Float* pdf) {
  *pdf = 0.f;
  hair_detail::Outgoing t;
  Vec3 w;
  if (!hair_detail::unit(wi, &w) || !hair_detail::outgoing_terms(fiber, wo, &t)) return Rgb(0.f);
  return hair_detail::eval(t, w, pdf);
}

TESSERA_HOST_DEVICE inline Rgb hair_f(const HairFiber& fiber, const Vec3& wo, const Vec3& wi) {
  Float pdf;
  return hair_f_pdf(fiber, wo, wi, &pdf);
}

TESSERA_HOST_DEVICE inline Float hair_pdf(const HairFiber& fiber, const Vec3& wo, const Vec3& wi) {
  Float pdf;
  hair_f_pdf(fiber, wo, wi, &pdf);
  return pdf;
}

TESSERA_HOST_DEVICE TESSERA_DEVICE_NOINLINE inline bool hair_sample(const HairFiber& fiber, const Vec3& wo, Float uc, Vec2 u,
                                                                    Vec3* wi, Rgb* f, Float* pdf) {
  using namespace hair_detail;
  constexpr Float kOneMinusEpsilon = 0x1.fffffep-1f;
  *pdf = 0.f;
  *f = Rgb(0.f);
  Outgoing t;
  if (!outgoing_terms(fiber, wo, &t)) return false;
  uc = clamp_nan(uc, 0.f, kOneMinusEpsilon);
  u.x = clamp_nan(u.x, 0.f, kOneMinusEpsilon);
  u.y = clamp_nan(u.y, 0.f, kOneMinusEpsilon);

  // Lobe p with probability ap_pdf[p]; uc's remainder rescaled to [0, 1).
  int p = -1;
  Float below = 0.f;
  for (int q = 0; q <= kPMax; ++q) {
    if (!(t.ap_pdf[q] > 0.f)) continue;
    p = q;  // rounding that leaves uc past the last sum falls into the last lobe
    if (uc < below + t.ap_pdf[q]) break;
    below += t.ap_pdf[q];
  }
  if (p < 0) return false;
  uc = clamp_nan((uc - below) / t.ap_pdf[p], 0.f, kOneMinusEpsilon);

  // theta_i from the lobe's von Mises-Fisher around its tilted reflection (pbrt-v4).
  const Float v = t.v[p];
  const Float cos_theta = 1.f + v * logf(fmaxf(u.x, 1e-5f) + (1.f - u.x) * expf(-2.f / v));
  const Float sin_theta = safe_sqrt(1.f - cos_theta * cos_theta);
  const Float sin_i =
      clamp_nan(-cos_theta * t.sin_o[p] + sin_theta * cosf(k2Pi * u.y) * t.cos_o[p], -1.f, 1.f);
  const Float cos_i = safe_sqrt(1.f - sin_i * sin_i);

  // phi_i about the lobe's deflection; uniform for the residual.
  const Float dphi = p < kPMax ? lobe_azimuth(p, t.gamma_o, t.gamma_t) + sample_trimmed_logistic(uc, t.s) : k2Pi * uc;
  const Float phi_i = t.phi_o + dphi;
  Vec3 w;
  if (!unit(Vec3(sin_i, cos_i * cosf(phi_i), cos_i * sinf(phi_i)), &w) || w.z == 0.f) return false;

  Float density;
  const Rgb value = eval(t, w, &density);
  if (!(density > 0.f)) return false;
  *wi = w;
  *f = value;
  *pdf = density;
  return true;
}

TESSERA_HOST_DEVICE inline Rgb hair_sigma_a_from_concentration(Float eumelanin, Float pheomelanin) {
  const Float ce = hair_detail::clamp_nan(eumelanin, 0.f, kInfinity);
  const Float cp = hair_detail::clamp_nan(pheomelanin, 0.f, kInfinity);
  return ce * Rgb(0.419f, 0.697f, 1.37f) + cp * Rgb(0.187f, 0.4f, 1.05f);
}

TESSERA_HOST_DEVICE inline Rgb hair_sigma_a_from_reflectance(const Rgb& c, Float beta_n) {
  using hair_detail::clamp_nan;
  const Float bn = clamp_nan(beta_n, 0.01f, 1.f);
  const Float bn2 = bn * bn, bn3 = bn2 * bn;
  const Float denom = 5.969f - 0.215f * bn + 2.532f * bn2 - 10.73f * bn3 + 5.574f * bn2 * bn2 + 0.245f * bn2 * bn3;
  Rgb sigma_a;
  for (int i = 0; i < 3; ++i) {
    const Float ci = clamp_nan(c[i], 0.f, 1.f);
    sigma_a[i] = ci > 0.f ? fminf(sqr(logf(ci) / denom), kInfinity) : kInfinity;
  }
  return sigma_a;
}

}  // namespace tessera
