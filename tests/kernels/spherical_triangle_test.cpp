// Uniform solid-angle sampling of triangles (kernels/spherical_triangle.h):
// the solid angle against a cube's known faces, every sample inside the
// triangle, and a chi-square test of uniformity over sub-triangles.
#include <gtest/gtest.h>

#include <cmath>

#include "kernels/rng.h"
#include "kernels/spherical_triangle.h"

namespace tessera {
namespace {

TEST(SphericalTriangle, SolidAngleOfHalfACubeFaceIsAThirdOfPi) {
  // From the centre of the cube [-1,1]^3, each face subtends 4 pi / 6 and
  // each half of a face (cut along a diagonal) pi / 3.
  const Vec3 p(0.f), v0(-1, -1, 1), v1(1, -1, 1), v2(1, 1, 1), v3(-1, 1, 1);
  EXPECT_NEAR(triangle_solid_angle(p, v0, v1, v2), kPi / 3, 1e-5);
  EXPECT_NEAR(triangle_solid_angle(p, v0, v2, v3), kPi / 3, 1e-5);
  // Small and far: about the area formula A cos / d^2.
  const Float d = 100.f;
  EXPECT_NEAR(triangle_solid_angle(p, Vec3(0, 0, d), Vec3(1, 0, d), Vec3(0, 1, d)), 0.5f / (d * d), 1e-3 * 0.5f / (d * d));
}

// Counts of directions landing in each of the four midpoint sub-triangles
// against their solid angles.
void expect_uniform(const Vec3& p, const Vec3& v0, const Vec3& v1, const Vec3& v2) {
  const Vec3 m01 = 0.5f * (v0 + v1), m12 = 0.5f * (v1 + v2), m20 = 0.5f * (v2 + v0);
  const Vec3 subs[4][3] = {{v0, m01, m20}, {m01, v1, m12}, {m20, m12, v2}, {m01, m12, m20}};
  const double total = triangle_solid_angle(p, v0, v1, v2);
  constexpr int kSamples = 200000;
  int counts[4] = {0, 0, 0, 0}, outside = 0;
  Rng rng = Rng::for_sample(17, 0, 0);
  for (int i = 0; i < kSamples; ++i) {
    Vec3 w;
    ASSERT_TRUE(sample_spherical_triangle(p, v0, v1, v2, Vec2(rng.uniform(), rng.uniform()), &w));
    ASSERT_NEAR(glm::length(w), 1.0, 1e-5);
    // Where the ray meets the plane, in barycentrics (unclamped).
    const Vec3 e1 = v1 - v0, e2 = v2 - v0, s1 = glm::cross(w, e2), d = p - v0;
    const Float div = glm::dot(s1, e1);
    const Float b1 = glm::dot(d, s1) / div, b2 = glm::dot(w, glm::cross(d, e1)) / div;
    if (b1 < -1e-3f || b2 < -1e-3f || b1 + b2 > 1.001f) ++outside;
    // Which sub-triangle: by the midpoint lines.
    const int sub = b1 >= 0.5f ? 1 : b2 >= 0.5f ? 2 : (b1 + b2 <= 0.5f ? 0 : 3);
    ++counts[sub];
  }
  EXPECT_EQ(outside, 0);
  double chi2 = 0;
  for (int k = 0; k < 4; ++k) {
    const double expected = kSamples * triangle_solid_angle(p, subs[k][0], subs[k][1], subs[k][2]) / total;
    chi2 += (counts[k] - expected) * (counts[k] - expected) / expected;
  }
  EXPECT_LT(chi2, 16.27) << "chi-square, 3 degrees of freedom, p = 0.001";
}

TEST(SphericalTriangle, SamplesAreUniformInSolidAngle) {
  expect_uniform(Vec3(0.f), Vec3(-1, -1, 1), Vec3(1, -1, 1), Vec3(1, 1, 1));          // large, seen square on
  expect_uniform(Vec3(0.3f, 0.2f, 0.f), Vec3(-2, 0, 0.2f), Vec3(2, 0.1f, 0.3f), Vec3(0, 3, 0.1f));  // grazing
  expect_uniform(Vec3(0.f), Vec3(0, 0, 5), Vec3(0.3f, 0, 5), Vec3(0, 0.2f, 5.2f));   // small
  expect_uniform(Vec3(0.f), Vec3(-3, 0.01f, 1), Vec3(3, 0.01f, 1), Vec3(0, 0.05f, 1));  // a thin sliver
}

}  // namespace
}  // namespace tessera
