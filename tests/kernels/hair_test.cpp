// Tests of the hair BSDF (src/kernels/hair.h), after pbrt-v4's Hair tests in
// bsdfs_test.cpp, with tolerances stated where they are checked.
//
//  * HairMp.*: Mp integrates to 1 over theta_i for every variance, both sides
//    of the v = 0.1 switch; log I0 against a double-precision reference.
//  * HairEnergy.WhiteFurnace: sigma_a = 0 loses nothing: the uniform-sphere
//    estimate of the integral of f |cos| is 1.
//  * HairSampling.*: sample weights f |cos| / pdf are 1 without absorption;
//    with absorption the importance-sampled and uniform estimates agree; the pdf
//    integrates to 1 and hair_pdf reproduces the sampled pdf; chi^2
//    goodness-of-fit of hair_sample against hair_pdf.
//  * HairFrame.*: the offset h derived from wo is the geometric one.
//  * HairRobustness.*: degenerate inputs give finite outputs.
//  * HairParams.*: melanin and colour to sigma_a.
//
// Integrals over the sphere use stratified uniform-sphere sampling (see
// integrate_sphere): pbrt-v4's uniform-sphere estimator, with strata in place
// of its quasi-random points and of its averaging over h (which smooths its
// integrand; ours has one h per wo), so that lobes a few hundredths of a
// radian wide are integrated to a few 1e-3.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <initializer_list>
#include <string>
#include <vector>

#include "kernels/hair.h"
#include "kernels/rng.h"
#include "kernels/sampling.h"
#include "chi2.h"

using namespace tessera;

namespace {

HairFiber fiber(Float beta_m, Float beta_n, Float alpha = 0.f, Rgb sigma_a = Rgb(0.f), Float eta = 1.55f) {
  HairFiber f;
  f.beta_m = beta_m;
  f.beta_n = beta_n;
  f.alpha = alpha;
  f.sigma_a = sigma_a;
  f.eta = eta;
  return f;
}

// The direction with sin theta = u (along the fiber) and azimuth phi about it.
Vec3 fiber_dir(double u, double phi) {
  const double r = std::sqrt(std::max(0.0, 1.0 - u * u));
  return Vec3(Float(u), Float(r * std::cos(phi)), Float(r * std::sin(phi)));
}

bool finite3(const Vec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

std::string describe(const HairFiber& h, const Vec3& wo) {
  char buf[200];
  std::snprintf(buf, sizeof buf, "beta_m=%.2f beta_n=%.2f alpha=%.1f sigma_a=(%.3f,%.3f,%.3f) wo=(%.4f,%.4f,%.4f)",
                h.beta_m, h.beta_n, h.alpha, h.sigma_a.x, h.sigma_a.y, h.sigma_a.z, wo.x, wo.y, wo.z);
  return buf;
}

// Integrals over the sphere of f(wo, wi) |wi.z| Li(wi) (per channel) and of
// hair_pdf(wo, wi), by stratified uniform-sphere sampling: n_theta bands
// equal in theta_i (not in u = sin theta_i, whose bands are too wide near the
// poles for the lobes there) times n_phi equal sectors, one uniform sample per
// stratum weighted by the stratum's solid angle. The counts follow the lobes'
// widths, six strata per standard deviation: sqrt(v) of the narrowest Mp
// (TT's, v0 / 4) in theta and the logistic's s pi / sqrt(3) in phi.
struct SphereIntegrals {
  double f[3] = {0, 0, 0};
  double pdf = 0;
  int samples = 0;
};
template <typename Li>
SphereIntegrals integrate_sphere(const HairFiber& h, const Vec3& wo, uint64_t seed, Li li) {
  const double bm = h.beta_m, bn = h.beta_n;
  const double sd_theta = 0.5 * (0.726 * bm + 0.812 * bm * bm + 3.7 * std::pow(bm, 20));
  const double sd_phi = 0.626657069 * (0.265 * bn + 1.194 * bn * bn + 5.372 * std::pow(bn, 22)) * M_PI / std::sqrt(3.0);
  const int n_theta = std::max(100, int(std::ceil(6 * M_PI / sd_theta)));
  const int n_phi = std::max(200, int(std::ceil(6 * 2 * M_PI / sd_phi)));
  Rng rng = Rng::for_sample(seed, 5, 9);
  SphereIntegrals out;
  for (int i = 0; i < n_theta; ++i) {
    const double u0 = std::sin(M_PI * (double(i) / n_theta - 0.5));
    const double u1 = std::sin(M_PI * (double(i + 1) / n_theta - 0.5));
    const double area = (u1 - u0) * 2 * M_PI / n_phi;
    double band[4] = {0, 0, 0, 0};
    for (int j = 0; j < n_phi; ++j) {
      const double u = u0 + (u1 - u0) * rng.uniform();
      const double phi = 2.0 * M_PI * (j + rng.uniform()) / n_phi;
      const Vec3 wi = fiber_dir(u, phi);
      Float pdf;
      const Rgb f = hair_f_pdf(h, wo, wi, &pdf) * std::abs(wi.z) * li(wi);
      for (int c = 0; c < 3; ++c) band[c] += f[c];
      band[3] += pdf;
    }
    for (int c = 0; c < 3; ++c) out.f[c] += band[c] * area;
    out.pdf += band[3] * area;
  }
  out.samples = n_theta * n_phi;
  return out;
}
Float unit_li(const Vec3&) { return 1.f; }

}  // namespace

// ----------------------------------------------------------------------- Mp ---
TEST(HairMp, LogI0MatchesReference) {
  for (double x : {0.0, 1e-3, 0.5, 2.0, 7.5, 11.9, 12.1, 20.0, 100.0, 1e4}) {
    // Reference: the power series in double, or the asymptotic series with six terms.
    double ref;
    if (x < 30) {
      double term = 1, sum = 1;
      for (int k = 1; k < 200; ++k) sum += (term *= 0.25 * x * x / (double(k) * k));
      ref = std::log(sum) - x;
    } else {
      double s = 1, c = 1;
      for (int k = 1; k < 6; ++k) s += (c *= (2.0 * k - 1) * (2.0 * k - 1) / (8.0 * k * x));
      ref = -0.5 * std::log(2 * M_PI * x) + std::log(s);
    }
    EXPECT_NEAR(hair_detail::log_i0_minus_x(Float(x)), ref, 2e-6 * std::max(1.0, std::abs(ref))) << "x = " << x;
  }
}

// The integral of Mp cos(theta_i) over theta_i is 1 for any variance and
// (tilted) theta_o: within 1e-4 by the trapezoid rule on 40001 points.
TEST(HairMp, Normalised) {
  for (double v : {2e-4, 0.003, 0.05, 0.0999, 0.1001, 0.5, 3.0, 100.0}) {
    for (double theta_o : {-1.5, -0.7, 0.0, 0.3, 1.2, 1.55}) {
      const int n = 40001;
      double sum = 0;
      for (int k = 0; k < n; ++k) {
        const double t = -M_PI / 2 + M_PI * k / (n - 1);
        const double w = (k == 0 || k == n - 1) ? 0.5 : 1.0;
        sum += w * hair_detail::longitudinal(Float(std::sin(t)), Float(std::cos(t)), Float(std::sin(theta_o)),
                                             Float(std::cos(theta_o)), Float(v)) *
               std::cos(t);
      }
      EXPECT_NEAR(sum * M_PI / (n - 1), 1.0, 1e-4) << "v = " << v << " theta_o = " << theta_o;
    }
  }
}

// ------------------------------------------------------------ white furnace ---
// pbrt-v4's Hair.WhiteFurnace: beta_m, beta_n in {0.1, 0.3, ..., 0.9}, no
// absorption, random wo: the integral of f |cos| over the sphere is 1. pbrt
// accepts 0.95..1.05; the stratified estimate here is held to 1 +- 0.02.
TEST(HairEnergy, WhiteFurnace) {
  Rng rng = Rng::for_sample(21, 0, 0);
  double worst = 0;
  for (Float bm : {0.1f, 0.3f, 0.5f, 0.7f, 0.9f}) {
    for (Float bn : {0.1f, 0.3f, 0.5f, 0.7f, 0.9f}) {
      for (Float alpha : {0.f, 2.f}) {
        const Vec3 wo = sample_uniform_sphere(rng.uniform2());
        const HairFiber h = fiber(bm, bn, alpha);
        const SphereIntegrals r = integrate_sphere(h, wo, 3, unit_li);
        for (int c = 0; c < 3; ++c) EXPECT_NEAR(r.f[c], 1.0, 0.02) << describe(h, wo);
        worst = std::max(worst, std::abs(r.f[0] - 1.0));
      }
    }
  }
  std::printf("[hair] white furnace: worst |integral - 1| = %.2e\n", worst);
}

// --------------------------------------------------------------- sampling ---
// pbrt-v4's Hair.SamplingWeights: without absorption every sample's weight
// f |cos| / pdf is 1 (the lobe choice is exactly proportional to A_p, which
// sum to 1): within 1e-3 per sample, and the mean within 1e-4.
TEST(HairSampling, WeightsAreOneWithoutAbsorption) {
  Rng rng = Rng::for_sample(22, 0, 0);
  double worst = 0;
  for (Float bm : {0.1f, 0.3f, 0.5f, 0.7f, 0.9f}) {
    for (Float bn : {0.2f, 0.4f, 0.6f, 0.8f, 1.0f}) {
      const HairFiber h = fiber(bm, bn, 2.f);
      double sum = 0;
      int accepted = 0;
      const int n = 4000;
      for (int i = 0; i < n; ++i) {
        const Vec3 wo = sample_uniform_sphere(rng.uniform2());
        const Float uc = rng.uniform();
        const Vec2 u = rng.uniform2();
        Vec3 wi;
        Rgb f;
        Float pdf;
        if (!hair_sample(h, wo, uc, u, &wi, &f, &pdf)) continue;
        ++accepted;
        for (int c = 0; c < 3; ++c) {
          const double w = f[c] * std::abs(wi.z) / pdf;
          worst = std::max(worst, std::abs(w - 1.0));
          ASSERT_NEAR(w, 1.0, 1e-3) << describe(h, wo) << " wi=(" << wi.x << "," << wi.y << "," << wi.z << ")";
          if (c == 0) sum += w;
        }
      }
      EXPECT_GE(accepted, n - 2) << describe(h, Vec3(0.f));
      EXPECT_NEAR(sum / accepted, 1.0, 1e-4);
    }
  }
  std::printf("[hair] sampling weights without absorption: worst |w - 1| = %.2e\n", worst);
}

// pbrt-v4's Hair.SamplingConsistency, per channel, with absorption and a
// non-uniform incident radiance: the importance-sampled estimate of the
// reflected radiance agrees with the stratified uniform one within 3 standard
// errors of the former plus 0.5 % (a bound on the latter's own error).
TEST(HairSampling, ConsistentWithUniformSampling) {
  Rng rng = Rng::for_sample(23, 0, 0);
  auto li = [](const Vec3& w) { return (1.2f + w.y) * (1.2f + 0.5f * w.x); };
  const Float configs[][2] = {{0.1f, 0.3f}, {0.2f, 0.5f}, {0.4f, 0.4f}, {0.6f, 0.8f}, {0.9f, 0.2f}};
  double worst_sigmas = 0, worst_rel = 0;
  for (const auto& cfg : configs) {
    for (int k = 0; k < 2; ++k) {
      const Rgb sigma_a = hair_sigma_a_from_concentration(0.2f + 2.f * rng.uniform(), rng.uniform());
      const HairFiber h = fiber(cfg[0], cfg[1], 2.f, sigma_a);
      const Vec3 wo = sample_uniform_sphere(rng.uniform2());
      const int n = 100000;
      double s[3] = {0, 0, 0}, s2[3] = {0, 0, 0};
      for (int i = 0; i < n; ++i) {
        Vec3 wi;
        Rgb f;
        Float pdf;
        const Float uc = rng.uniform();
        const Vec2 u = rng.uniform2();
        if (!hair_sample(h, wo, uc, u, &wi, &f, &pdf)) continue;
        const Rgb w = f * std::abs(wi.z) * li(wi) / pdf;
        for (int c = 0; c < 3; ++c) {
          s[c] += w[c];
          s2[c] += double(w[c]) * w[c];
        }
      }
      const SphereIntegrals r = integrate_sphere(h, wo, 4, li);
      for (int c = 0; c < 3; ++c) {
        const double mean = s[c] / n, se = std::sqrt(std::max(0.0, s2[c] / n - mean * mean) / n);
        EXPECT_NEAR(mean, r.f[c], 3 * se + 5e-3 * r.f[c]) << describe(h, wo) << " channel " << c;
        if (se > 0) worst_sigmas = std::max(worst_sigmas, std::abs(mean - r.f[c]) / se);
        worst_rel = std::max(worst_rel, std::abs(mean - r.f[c]) / r.f[c]);
      }
    }
  }
  std::printf("[hair] importance vs uniform: worst difference %.2f standard errors, relative %.2e\n", worst_sigmas,
              worst_rel);
}

// The pdf integrates to 1 over the sphere (within 0.01, a few times the
// stratified estimate's own error), and hair_f and hair_pdf at a
// sampled direction are what hair_sample returned, bit for bit.
TEST(HairSampling, PdfIntegratesToOneAndMatchesSample) {
  Rng rng = Rng::for_sample(24, 0, 0);
  double worst = 0;
  for (Float bm : {0.1f, 0.4f, 0.8f}) {
    for (Float bn : {0.1f, 0.4f, 0.8f}) {
      const HairFiber h = fiber(bm, bn, 2.f, Rgb(0.3f, 0.8f, 2.f));
      const Vec3 wo = sample_uniform_sphere(rng.uniform2());
      const SphereIntegrals r = integrate_sphere(h, wo, 5, unit_li);
      EXPECT_NEAR(r.pdf, 1.0, 0.01) << describe(h, wo);
      worst = std::max(worst, std::abs(r.pdf - 1.0));
      for (int i = 0; i < 2000; ++i) {
        Vec3 wi;
        Rgb f;
        Float pdf;
        const Float uc = rng.uniform();
        const Vec2 u = rng.uniform2();
        if (!hair_sample(h, wo, uc, u, &wi, &f, &pdf)) continue;
        EXPECT_EQ(hair_pdf(h, wo, wi), pdf) << describe(h, wo);
        EXPECT_EQ(hair_f(h, wo, wi), f) << describe(h, wo);
        EXPECT_NEAR(glm::length(wi), 1.f, 1e-5f);
      }
    }
  }
  std::printf("[hair] worst |integral of pdf - 1| = %.2e\n", worst);
}

// ------------------------------------------------------------------- chi^2 ---
// Histogram of hair_sample over n_u x n_phi cells of (u = wi.x, phi_i)
// covering the sphere against the integral of hair_pdf over each cell
// (composite Simpson in (u, phi), whose measure is solid angle), cells with
// fewer than 5 expected samples pooled, Pearson chi^2 at significance 0.01
// with a Sidak correction for the number of tests.
namespace {

constexpr int kURes = 40, kPhiRes = 80, kChi2Samples = 400000, kSimpsonSub = 10;
constexpr int kNumChi2Tests = 4;

struct Chi2Outcome {
  double pvalue = 0, pdf_integral = 0, accepted = 0;
  std::string detail;
};

Chi2Outcome chi2_test(const HairFiber& sampled, const HairFiber& claimed, const Vec3& wo, uint64_t seed) {
  std::vector<double> obs(kURes * kPhiRes, 0.0), expct(kURes * kPhiRes, 0.0);
  Rng rng = Rng::for_sample(seed, 7, 11);
  int accepted = 0;
  for (int i = 0; i < kChi2Samples; ++i) {
    Vec3 wi;
    Rgb f;
    Float pdf;
    const Float uc = rng.uniform();
    const Vec2 u = rng.uniform2();
    if (!hair_sample(sampled, wo, uc, u, &wi, &f, &pdf)) continue;
    double phi = std::atan2(double(wi.z), double(wi.y));
    if (phi < 0) phi += 2 * M_PI;
    const int iu = std::clamp(int((wi.x + 1.0) * 0.5 * kURes), 0, kURes - 1);
    const int ip = std::clamp(int(phi / (2 * M_PI) * kPhiRes), 0, kPhiRes - 1);
    obs[iu * kPhiRes + ip] += 1;
    ++accepted;
  }
  double total = 0;
  for (int iu = 0; iu < kURes; ++iu) {
    for (int ip = 0; ip < kPhiRes; ++ip) {
      const double u0 = -1.0 + 2.0 * iu / kURes, du = 2.0 / kURes / kSimpsonSub;
      const double p0 = 2 * M_PI * ip / kPhiRes, dp = 2 * M_PI / kPhiRes / kSimpsonSub;
      double sum = 0;
      for (int a = 0; a <= kSimpsonSub; ++a) {
        const double wa = (a == 0 || a == kSimpsonSub) ? 1 : (a % 2 ? 4 : 2);
        for (int b = 0; b <= kSimpsonSub; ++b) {
          const double wb = (b == 0 || b == kSimpsonSub) ? 1 : (b % 2 ? 4 : 2);
          sum += wa * wb * hair_pdf(claimed, wo, fiber_dir(u0 + a * du, p0 + b * dp));
        }
      }
      const double integral = sum * du * dp / 9.0;
      expct[iu * kPhiRes + ip] = integral * kChi2Samples;
      total += integral;
    }
  }
  std::vector<int> order(obs.size());
  for (size_t i = 0; i < order.size(); ++i) order[i] = int(i);
  std::sort(order.begin(), order.end(), [&](int x, int y) { return expct[x] < expct[y]; });
  double pooled_obs = 0, pooled_exp = 0, chsq = 0;
  int dof = 0;
  for (int i : order) {
    if (expct[i] < 5) {
      pooled_obs += obs[i];
      pooled_exp += expct[i];
    } else {
      chsq += (obs[i] - expct[i]) * (obs[i] - expct[i]) / expct[i];
      ++dof;
    }
  }
  if (pooled_exp > 0) {
    chsq += (pooled_obs - pooled_exp) * (pooled_obs - pooled_exp) / pooled_exp;
    ++dof;
  }
  dof -= 1;
  Chi2Outcome out;
  out.pvalue = dof > 0 ? chi2::chi2_survival(chsq, dof) : 1.0;
  out.pdf_integral = total;
  out.accepted = double(accepted) / kChi2Samples;
  char buf[160];
  std::snprintf(buf, sizeof buf, "chi2=%.1f dof=%d p=%.3g pdf integral=%.5f accepted=%.5f", chsq, dof, out.pvalue,
                total, out.accepted);
  out.detail = buf;
  return out;
}

}  // namespace

TEST(HairSampling, Chi2) {
  struct Config {
    HairFiber h;
    Vec3 wo;
  };
  const Config configs[kNumChi2Tests] = {
      {fiber(0.1f, 0.3f, 2.f, Rgb(0.2f, 0.4f, 0.9f)), glm::normalize(Vec3(0.3f, 0.5f, 0.8f))},
      {fiber(0.8f, 0.5f, 2.f, Rgb(0.1f)), glm::normalize(Vec3(-0.6f, -0.2f, 0.7f))},
      {fiber(0.3f, 0.1f, 5.f), glm::normalize(Vec3(0.1f, -0.9f, 0.3f))},
      {fiber(0.25f, 0.9f, -3.f, Rgb(1.5f, 2.f, 3.f)), glm::normalize(Vec3(0.85f, 0.1f, 0.5f))},
  };
  const double significance = 1.0 - std::pow(1.0 - 0.01, 1.0 / kNumChi2Tests);
  uint64_t seed = 30;
  for (const Config& c : configs) {
    const Chi2Outcome r = chi2_test(c.h, c.h, c.wo, seed++);
    std::printf("[hair] chi2 %s: %s\n", describe(c.h, c.wo).c_str(), r.detail.c_str());
    EXPECT_GE(r.pvalue, significance) << describe(c.h, c.wo) << " " << r.detail;
    EXPECT_NEAR(r.pdf_integral, 1.0, 2e-3) << r.detail;
    EXPECT_GT(r.accepted, 0.9999) << r.detail;
  }
}

// The chi^2 test has teeth: a pdf 10 % off in either roughness or with a 1
// degree different tilt is rejected.
TEST(HairSampling, Chi2DetectsWrongPdf) {
  const Vec3 wo = glm::normalize(Vec3(0.3f, 0.5f, 0.8f));
  const HairFiber h = fiber(0.3f, 0.3f, 2.f, Rgb(0.2f));
  const HairFiber wrong[3] = {fiber(0.33f, 0.3f, 2.f, Rgb(0.2f)), fiber(0.3f, 0.33f, 2.f, Rgb(0.2f)),
                              fiber(0.3f, 0.3f, 3.f, Rgb(0.2f))};
  for (int i = 0; i < 3; ++i) {
    const Chi2Outcome r = chi2_test(h, wrong[i], wo, 40 + i);
    std::printf("[hair] chi2 against a wrong pdf (%s): %s\n", describe(wrong[i], wo).c_str(), r.detail.c_str());
    EXPECT_LT(r.pvalue, 1e-6);
  }
}

// ------------------------------------------------------------------- frame ---
// The h that hair_offset derives from wo is the offset at which the ray hit
// the fiber, in pbrt-v4's convention: a unit-radius round fiber along a
// random tangent x, a ray of random direction d at offset h0 along
// y_p = cross(z_p, x), where z_p is d made orthogonal to x (pbrt's ribbon
// normal, pointing along the ray); the hit's outward normal n gives our frame
// (x, cross(n, x), n), in which wo = -d. Within 2e-5 (float rounding).
TEST(HairFrame, OffsetFromWoIsTheHitOffset) {
  Rng rng = Rng::for_sample(25, 0, 0);
  double worst = 0;
  for (int i = 0; i < 20000; ++i) {
    const glm::dvec3 x = glm::dvec3(sample_uniform_sphere(rng.uniform2()));
    const glm::dvec3 d = glm::dvec3(sample_uniform_sphere(rng.uniform2()));
    const glm::dvec3 d_perp = d - glm::dot(d, x) * x;
    if (glm::length(d_perp) < 0.05) continue;  // a ray along the fiber hits its end, not its side
    const glm::dvec3 z_p = glm::normalize(d_perp), y_p = glm::cross(z_p, x);
    const double h0 = -0.999 + 1.998 * rng.uniform();
    const double radius = 0.01 + 3.0 * rng.uniform();
    // Ray from far behind the fiber (along -d) through the offset h0 * radius.
    const glm::dvec3 axis_point = glm::dvec3(rng.uniform(), rng.uniform(), rng.uniform()) * 5.0;
    const glm::dvec3 o = axis_point + h0 * radius * y_p - 20.0 * radius * d / glm::length(d_perp);
    // |q + t d_perp|^2 = radius^2 with q = (o - axis_point) made orthogonal to x.
    const glm::dvec3 q = (o - axis_point) - glm::dot(o - axis_point, x) * x;
    const double A = glm::dot(d_perp, d_perp), B = 2.0 * glm::dot(q, d_perp), C = glm::dot(q, q) - radius * radius;
    const double disc = B * B - 4 * A * C;
    ASSERT_GT(disc, 0.0);
    const double t = (-B - std::sqrt(disc)) / (2 * A);  // the first (front) hit
    const glm::dvec3 p = o + t * d;
    const glm::dvec3 n = glm::normalize((p - axis_point) - glm::dot(p - axis_point, x) * x);
    const glm::dvec3 y = glm::cross(n, x);
    const Vec3 wo_local(Float(glm::dot(-d, x)), Float(glm::dot(-d, y)), Float(glm::dot(-d, n)));
    ASSERT_GT(wo_local.z, 0.f);  // the viewer sees the front of the fiber
    const double h = hair_offset(wo_local);
    EXPECT_NEAR(h, h0, 2e-5) << "tangent (" << x.x << "," << x.y << "," << x.z << ") d (" << d.x << "," << d.y << ","
                             << d.z << ")";
    worst = std::max(worst, std::abs(h - h0));
  }
  std::printf("[hair] worst |hair_offset - h0| = %.2e\n", worst);
  EXPECT_EQ(hair_offset(Vec3(1.f, 0.f, 0.f)), 0.f);
  EXPECT_EQ(hair_offset(Vec3(0.f, 1e-30f, 1e-30f)), hair_offset(Vec3(0.f, 1.f, 1.f)));
  EXPECT_EQ(hair_offset(Vec3(0.f, -3.f, 0.f)), -1.f);
}

// The azimuths follow pbrt-v4 (its lobe centres -2 gamma_o + p (2 gamma_t +
// pi) with gamma_o = asin(h)): with TT and TRT absorbed away, the R lobe of a
// smooth fiber peaks at phi_i = phi_o - 2 asin(h). (On a true cylinder the
// mirror direction is phi_o + 2 asin(h): pbrt's R is its mirror image about
// the normal plane's z; see the header.)
TEST(HairFrame, RLobeAtPbrtAzimuth) {
  const HairFiber h = fiber(0.1f, 0.1f, 0.f, Rgb(1e4f));
  for (double h0 : {-0.6, -0.2, 0.3, 0.7}) {
    const double phi_o = std::acos(h0);  // wo = (0, h0, sqrt(1 - h0^2))
    const Vec3 wo = fiber_dir(0.0, phi_o);
    ASSERT_NEAR(hair_offset(wo), h0, 1e-6);
    double best = -1, best_phi = 0;
    for (int k = 0; k < 3600; ++k) {
      const double phi = 2 * M_PI * k / 3600;
      const double v = hair_f(h, wo, fiber_dir(0.0, phi)).x * std::abs(std::sin(phi));
      if (v > best) best = v, best_phi = phi;
    }
    const double expected = std::remainder(phi_o - 2 * std::asin(h0), 2 * M_PI);
    EXPECT_NEAR(std::remainder(best_phi - expected, 2 * M_PI), 0.0, 0.01) << "h = " << h0;
  }
}

// -------------------------------------------------------------- robustness ---
TEST(HairRobustness, DegenerateInputsGiveFiniteOutputs) {
  const Float nan = std::nanf(""), inf = INFINITY;
  const Vec3 dirs[] = {Vec3(0.f),
                       Vec3(nan, 0.f, 1.f),
                       Vec3(0.f, inf, 1.f),
                       Vec3(-inf, 0.f, 0.f),
                       Vec3(1.f, 0.f, 0.f),
                       Vec3(-1.f, 0.f, 0.f),
                       Vec3(0.f, 1.f, 0.f),
                       Vec3(0.f, -1.f, 0.f),
                       Vec3(0.f, 0.f, 1.f),
                       Vec3(0.f, 0.f, -1.f),
                       Vec3(1.f, 1e-30f, 1e-30f),
                       Vec3(1e-40f, 1e-40f, 0.f),
                       Vec3(3e38f, 3e38f, 3e38f),
                       Vec3(0.3f, 0.4f, 0.5f),
                       glm::normalize(Vec3(0.9999f, 0.f, 0.0141f)),
                       glm::normalize(Vec3(0.2f, -0.7f, 1e-7f))};
  std::vector<HairFiber> fibers = {fiber(0.3f, 0.3f, 2.f)};
  fibers.push_back(fiber(0.f, 0.f));
  fibers.push_back(fiber(1.f, 1.f, 90.f));
  fibers.push_back(fiber(nan, nan, nan, Rgb(nan), nan));
  fibers.push_back(fiber(-1.f, 5.f, -1e10f, Rgb(-1.f), 0.f));
  fibers.push_back(fiber(0.01f, 0.01f, 2.f, Rgb(inf), 1.f));
  fibers.push_back(fiber(0.3f, 0.3f, 2.f, Rgb(3e38f, 0.f, 1e-30f), 0.5f));
  fibers.push_back(fiber(0.05f, 0.9f, 2.f, Rgb(0.f), 1e6f));
  const Float us[] = {0.f, 0.5f, 0x1.fffffep-1f, 1.f, -0.f, nan, inf, -inf, 2.f};
  int samples = 0;
  for (const HairFiber& h : fibers) {
    for (const Vec3& wo : dirs) {
      for (const Vec3& wi : dirs) {
        Float pdf;
        const Rgb f = hair_f_pdf(h, wo, wi, &pdf);
        ASSERT_TRUE(finite3(f) && std::isfinite(pdf)) << describe(h, wo);
        ASSERT_TRUE(f.x >= 0 && f.y >= 0 && f.z >= 0 && pdf >= 0) << describe(h, wo);
        ASSERT_TRUE(finite3(hair_f(h, wo, wi)) && std::isfinite(hair_pdf(h, wo, wi)));
      }
      for (Float uc : us) {
        for (Float u0 : us) {
          for (Float u1 : {0.f, 0.25f, nan, 1.f}) {
            Vec3 wi(7.f);
            Rgb f(7.f);
            Float pdf = 7.f;
            if (hair_sample(h, wo, uc, Vec2(u0, u1), &wi, &f, &pdf)) {
              ++samples;
              ASSERT_TRUE(finite3(wi) && finite3(f) && std::isfinite(pdf)) << describe(h, wo);
              ASSERT_GT(pdf, 0.f);
              ASSERT_NEAR(glm::length(wi), 1.f, 1e-5f);
              ASSERT_NE(wi.z, 0.f);
            } else {
              ASSERT_TRUE(finite3(f) && std::isfinite(pdf));
            }
          }
        }
      }
    }
  }
  EXPECT_GT(samples, 1000);  // most degenerate fibers still sample
  // Random directions, including unnormalised ones, and random parameters.
  Rng rng = Rng::for_sample(26, 0, 0);
  for (int i = 0; i < 50000; ++i) {
    const HairFiber h = fiber(rng.uniform(), rng.uniform(), 20.f * rng.uniform() - 10.f,
                              Rgb(10.f * rng.uniform(), rng.uniform(), 0.f), 1.f + rng.uniform());
    const Vec3 wo = sample_uniform_sphere(rng.uniform2()) * (0.5f + rng.uniform());
    const Vec3 wi = sample_uniform_sphere(rng.uniform2());
    Float pdf;
    const Rgb f = hair_f_pdf(h, wo, wi, &pdf);
    ASSERT_TRUE(finite3(f) && std::isfinite(pdf) && pdf >= 0);
    Vec3 ws;
    Rgb fs;
    Float ps;
    const Float uc = rng.uniform();
    const Vec2 u = rng.uniform2();
    if (hair_sample(h, wo, uc, u, &ws, &fs, &ps)) {
      ASSERT_TRUE(finite3(ws) && finite3(fs) && std::isfinite(ps) && ps > 0);
    }
  }
}

// ------------------------------------------------------------- parameters ---
TEST(HairParams, SigmaAFromConcentration) {
  const Rgb s = hair_sigma_a_from_concentration(1.3f, 0.f);
  EXPECT_FLOAT_EQ(s.x, 1.3f * 0.419f);
  EXPECT_FLOAT_EQ(s.y, 1.3f * 0.697f);
  EXPECT_FLOAT_EQ(s.z, 1.3f * 1.37f);
  const Rgb p = hair_sigma_a_from_concentration(0.f, 2.f);
  EXPECT_FLOAT_EQ(p.x, 2.f * 0.187f);
  EXPECT_FLOAT_EQ(p.y, 2.f * 0.4f);
  EXPECT_FLOAT_EQ(p.z, 2.f * 1.05f);
  const Rgb m = hair_sigma_a_from_concentration(0.5f, 0.25f);
  EXPECT_FLOAT_EQ(m.y, 0.5f * 0.697f + 0.25f * 0.4f);
  EXPECT_EQ(hair_sigma_a_from_concentration(-1.f, std::nanf("")), Rgb(0.f));
}

TEST(HairParams, SigmaAFromReflectance) {
  for (Float bn : {0.1f, 0.3f, 0.6f, 1.f}) {
    EXPECT_EQ(hair_sigma_a_from_reflectance(Rgb(1.f), bn), Rgb(0.f));
    // pbrt-v4's formula at one point: (log(0.5) / poly(beta_n))^2.
    const double poly = 5.969 - 0.215 * bn + 2.532 * bn * bn - 10.73 * std::pow(bn, 3) + 5.574 * std::pow(bn, 4) +
                        0.245 * std::pow(bn, 5);
    EXPECT_NEAR(hair_sigma_a_from_reflectance(Rgb(0.5f), bn).x, std::pow(std::log(0.5) / poly, 2), 1e-6);
    // Darker colour, more absorption.
    Float prev = 0.f;
    for (Float c = 0.95f; c > 0.f; c -= 0.05f) {
      const Float s = hair_sigma_a_from_reflectance(Rgb(c), bn).x;
      EXPECT_GT(s, prev) << "c = " << c;
      prev = s;
    }
  }
  const Rgb mixed = hair_sigma_a_from_reflectance(Rgb(0.8f, 0.5f, 0.2f), 0.3f);
  EXPECT_LT(mixed.x, mixed.y);
  EXPECT_LT(mixed.y, mixed.z);
  // Out-of-range colours are clamped to [0, 1], as pbrt-v4's material does.
  EXPECT_EQ(hair_sigma_a_from_reflectance(Rgb(2.f), 0.3f), Rgb(0.f));
  const Rgb black = hair_sigma_a_from_reflectance(Rgb(0.f, -1.f, std::nanf("")), 0.3f);
  for (int c = 0; c < 3; ++c) EXPECT_TRUE(std::isfinite(black[c]) && black[c] > 1e30f);
}
