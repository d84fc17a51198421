// The density MIS weighs the coated BSDFs by: pbrt-v4's stochastic
// LayeredBxDF::PDF (bsdf_mis_pdf), and the heuristic its integrator uses.
#include <gtest/gtest.h>

#include <cmath>

#include "kernels/bsdf.h"
#include "render_helpers.h"

namespace tessera {
namespace {

constexpr Float kUniformSphere = 1.f / (4.f * kPi);

BsdfParams coat(BsdfType type, Float coat_alpha) {
  BsdfParams b;
  b.type = type;
  b.reflectance = Rgb(0.6f, 0.4f, 0.2f);
  b.eta = Rgb(0.143f, 0.374f, 1.442f);  // gold, for the conductor base
  b.k = Rgb(3.983f, 2.385f, 1.603f);
  b.base_alpha_x = b.base_alpha_y = 0.045f;
  b.ior = 1.5f;
  b.alpha_x = b.alpha_y = coat_alpha;
  return b;
}

Vec3 direction(Float theta, Float phi) {
  return Vec3(std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi), std::cos(theta));
}

TEST(LayeredMisPdf, SmoothCoatOverDiffuseIsPbrtV4sClosedForm) {
  // A smooth coat refracts both directions deterministically: pbrt-v4's
  // estimate is then 0.1 / (4 pi) + 0.9 cos(theta_t) / pi, theta_t the
  // refracted angle of wi, whatever the random numbers.
  const BsdfParams b = coat(BsdfType::CoatedDiffuse, 0.f);
  const Vec3 wo = direction(0.3f, 0.2f);
  for (Float theta : {0.1f, 0.7f, 1.2f, 1.5f}) {
    const Vec3 wi = direction(theta, 2.f);
    const Float sin_t = std::sin(theta) / 1.5f, cos_t = std::sqrt(1.f - sin_t * sin_t);
    EXPECT_NEAR(bsdf_mis_pdf(b, wo, wi), 0.1f * kUniformSphere + 0.9f * cos_t / kPi, 1e-5f) << theta;
    EXPECT_NEAR(bsdf_mis_pdf(b, -wo, -wi), bsdf_mis_pdf(b, wo, wi), 1e-6f);  // two-sided
  }
}

TEST(LayeredMisPdf, RoughCoatsGiveAPureFiniteFunctionWithTheCoatsLobe) {
  for (BsdfType type : {BsdfType::CoatedDiffuse, BsdfType::CoatedConductor}) {
    const BsdfParams b = coat(type, 0.14f);
    for (Float to : {0.05f, 0.6f, 1.45f})
      for (Float ti : {0.05f, 0.8f, 1.5f})
        for (Float phi : {0.f, 1.f, 3.1f}) {
          const Vec3 wo = direction(to, 0.f), wi = direction(ti, phi);
          const Float p = bsdf_mis_pdf(b, wo, wi);
          EXPECT_TRUE(std::isfinite(p) && p >= 0.1f * kUniformSphere) << p;
          EXPECT_EQ(p, bsdf_mis_pdf(b, wo, wi));  // seeded by the directions
          EXPECT_EQ(bsdf_mis_pdf(b, wo, -wi), 0.1f * kUniformSphere);  // the base is opaque
        }
    // At the mirror direction the coat's whole reflection lobe counts (pbrt-v4
    // evaluates the top with the reflection flag alone): far above the bsdf's own density.
    const Vec3 wo = direction(0.5f, 0.f), mirror(-wo.x, -wo.y, wo.z);
    EXPECT_GT(bsdf_mis_pdf(b, wo, mirror), 1.2f * bsdf_pdf(b, wo, mirror)) << int(type);
  }
  // Other BSDFs weigh by their own density.
  BsdfParams conductor = coat(BsdfType::Conductor, 0.2f);
  const Vec3 wo = direction(0.4f, 0.f), wi = direction(0.6f, 2.5f);
  EXPECT_EQ(bsdf_mis_pdf(conductor, wo, wi), bsdf_pdf(conductor, wo, wi));
}

TEST(LayeredMisPdf, TheHeuristicFollowsTheScenesIntegrator) {
  auto balance = [](const std::string& integrator) {
    SceneDesc d = load_pbrt_string(integrator + "WorldBegin\nShape \"sphere\"\n", "<test>", ".");
    return SceneData(std::move(d)).view().layered_mis_balance;
  };
  EXPECT_TRUE(balance(""));  // pbrt-v4's default, volpath: the balance heuristic
  EXPECT_TRUE(balance("Integrator \"volpath\"\n"));
  EXPECT_TRUE(balance("Integrator \"bdpt\"\n"));
  EXPECT_FALSE(balance("Integrator \"path\"\n"));  // the power heuristic
}

}  // namespace
}  // namespace tessera
