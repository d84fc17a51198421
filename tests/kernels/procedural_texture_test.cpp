// pbrt-v4's procedural textures and texture mappings, against values of a
// separate double-precision transcription of pbrt-v4's noise.cpp and
// textures.cpp (zero filter footprint: every octave summed), and against
// the mappings' geometry.
#include <gtest/gtest.h>

#include <cmath>

#include "kernels/procedural_texture.h"
#include "kernels/rng.h"
#include "kernels/texture_mapping.h"

#include <glm/gtc/matrix_transform.hpp>

namespace tessera {
namespace {

TEST(ProceduralTexture, FbmAndTurbulenceMatchPbrtV4) {
  struct Case {
    Vec3 p;
    double fbm8, turbulence8, fbm3_07, windy;
  };
  const Case cases[] = {
      {Vec3(0.3f, 0.7f, 1.1f), -0.36001112408935976, 0.44777738053383004, -0.4651549597170797, -0.13465286894270567},
      {Vec3(-2.25f, 5.5f, 0.125f), 0.1329119885668924, 0.2712148569775493, 0.2862757467517157, 0.059554864777056335},
      {Vec3(10.1f, -3.3f, 7.7f), 0.25622976501299394, 0.6418788476359024, 0.256819838838361, 0.05758411805162133},
      {Vec3(0.05f, 0.05f, 0.05f), 0.25416264579153725, 0.3018135106628786, 0.3621565398925058, 0.007689761862713665},
  };
  for (const Case& c : cases) {
    EXPECT_NEAR(fbm_noise(c.p, 0.5f, 8), c.fbm8, 1e-4) << c.p.x;
    EXPECT_NEAR(turbulence_noise(c.p, 0.5f, 8), c.turbulence8, 1e-4) << c.p.x;
    EXPECT_NEAR(fbm_noise(c.p, 0.7f, 3), c.fbm3_07, 1e-4) << c.p.x;
    EXPECT_NEAR(windy_value(c.p), c.windy, 1e-4) << c.p.x;
  }
}

TEST(ProceduralTexture, OneOctaveIsNoiseAndTurbulenceIsPositive) {
  Rng rng = Rng::for_sample(4, 5, 6);
  for (int i = 0; i < 2000; ++i) {
    const Vec3 p(rng.uniform() * 40.f - 20.f, rng.uniform() * 40.f - 20.f, rng.uniform() * 40.f - 20.f);
    ASSERT_EQ(fbm_noise(p, 0.5f, 1), perlin_noise(p));
    ASSERT_EQ(fbm_noise(p, 0.5f, 0), 0.f);
    ASSERT_GE(turbulence_noise(p, 0.5f, 8), 0.2f * std::pow(0.5f, 8.f) * 0.999f);
  }
  // Non-finite points read 0 noise in every octave; nothing is NaN.
  EXPECT_EQ(fbm_noise(Vec3(NAN, 0.f, 0.f), 0.5f, 8), 0.f);
  EXPECT_TRUE(std::isfinite(turbulence_noise(Vec3(INFINITY, 1.f, 2.f), 0.5f, 8)));
}

// pbrt-v4's MarbleTexture::Evaluate with octaves 8, roughness 0.5, scale 1,
// variation 0.2 (the defaults) and with 4, 0.6, 2.5, 0.5.
TEST(ProceduralTexture, MarbleMatchesPbrtV4) {
  struct Case {
    Vec3 p;
    Rgb defaults, other;
  };
  const Case cases[] = {
      {Vec3(0.3f, 0.7f, 1.1f), Rgb(0.6176311f, 0.6174303f, 0.7199985f), Rgb(0.8466387f, 0.8466387f, 0.8834012f)},
      {Vec3(-2.25f, 5.5f, 0.125f), Rgb(0.7701279f, 0.7701279f, 0.7751599f), Rgb(0.6715118f, 0.6715118f, 0.7589689f)},
      {Vec3(10.1f, -3.3f, 7.7f), Rgb(0.8457318f, 0.8390723f, 0.8396967f), Rgb(0.8659817f, 0.8659817f, 0.8949771f)},
      {Vec3(0.05f, 0.05f, 0.05f), Rgb(0.8424313f, 0.8358103f, 0.8357444f), Rgb(0.8711438f, 0.8704191f, 0.8981682f)},
  };
  for (const Case& c : cases) {
    const Rgb a = marble_value(c.p, 0.2f, 0.5f, 8), b = marble_value(2.5f * c.p, 0.5f, 0.6f, 4);
    for (int k = 0; k < 3; ++k) {
      EXPECT_NEAR(a[k], c.defaults[k], 2e-4f) << c.p.x << " channel " << k;
      EXPECT_NEAR(b[k], c.other[k], 2e-4f) << c.p.x << " channel " << k;
    }
  }
  EXPECT_TRUE(is_finite(marble_value(Vec3(NAN), 0.2f, 0.5f, 8)));
}

// Dots of radius 0.35 in the cells whose noise is positive (pbrt-v4's
// InsidePolkaDot): (0, 1) and (2, 2) lie in dots, (0, 0) and (-1, 0) in
// cells without one; about 15 % of the plane is covered.
TEST(ProceduralTexture, PolkaDotsWhereAndHowManyAsPbrtV4) {
  EXPECT_TRUE(inside_polka_dot(Vec2(0.f, 1.f)));
  EXPECT_TRUE(inside_polka_dot(Vec2(2.f, 2.f)));
  EXPECT_TRUE(inside_polka_dot(Vec2(-3.f, -2.1f)));
  EXPECT_FALSE(inside_polka_dot(Vec2(0.f, 0.f)));
  EXPECT_FALSE(inside_polka_dot(Vec2(-1.f, 0.f)));
  EXPECT_FALSE(inside_polka_dot(Vec2(-3.f, -3.f)));
  int inside = 0;
  for (int i = 0; i < 40; ++i)
    for (int j = 0; j < 40; ++j) inside += inside_polka_dot(Vec2(-3.f + 0.15f * i, -3.f + 0.15f * j));
  EXPECT_NEAR(inside, 241, 3);  // the transcription counts 241 of these 1600 points
  EXPECT_FALSE(inside_polka_dot(Vec2(NAN, 0.f)));
  EXPECT_FALSE(inside_polka_dot(Vec2(1e30f, 0.f)));
}

TEST(TextureMapping, SphericalAndCylindricalAnglesAsPbrtV4) {
  auto near2 = [](Vec2 a, Vec2 b) { return std::abs(a.x - b.x) < 1e-6f && std::abs(a.y - b.y) < 1e-6f; };
  EXPECT_TRUE(near2(spherical_st(Vec3(0.f, 0.f, 2.f)), Vec2(0.f, 0.f)));      // the pole: theta 0
  EXPECT_TRUE(near2(spherical_st(Vec3(3.f, 0.f, 0.f)), Vec2(0.5f, 0.f)));     // the equator at phi 0
  EXPECT_TRUE(near2(spherical_st(Vec3(0.f, 1.f, 0.f)), Vec2(0.5f, 0.25f)));   // phi pi/2
  EXPECT_TRUE(near2(spherical_st(Vec3(0.f, -1.f, -1e-9f)), Vec2(0.5f, 0.75f)));  // phi wraps to [0, 2 pi)
  EXPECT_TRUE(near2(spherical_st(Vec3(0.f, 0.f, -5.f)), Vec2(1.f, 0.f)));
  EXPECT_TRUE(near2(spherical_st(Vec3(0.f)), Vec2(0.f)));
  EXPECT_TRUE(near2(cylindrical_st(Vec3(1.f, 0.f, 2.5f)), Vec2(0.5f, 2.5f)));
  EXPECT_TRUE(near2(cylindrical_st(Vec3(0.f, 1.f, -1.f)), Vec2(0.75f, -1.f)));
  EXPECT_TRUE(near2(cylindrical_st(Vec3(0.f, -1.f, 0.f)), Vec2(0.25f, 0.f)));
}

TEST(TextureMapping, PlanarAndUvCoordinates) {
  Texture t;
  t.su = 2.f;
  t.sv = 3.f;
  t.du = 0.5f;
  t.dv = -1.f;
  const TexturePoint tp{Vec3(1.f, 2.f, 3.f), Vec3(0.f, 0.f, 1.f), Vec2(0.25f, 0.5f)};
  EXPECT_EQ(texture_st(t, tp), Vec2(1.f, 0.5f));
  t.mapping = TextureMapping::Planar;
  t.vs = Vec3(0.f, 0.f, 1.f);
  t.vt = Vec3(1.f, 1.f, 0.f);
  t.texture_from_render = glm::translate(Mat4(1.f), Vec3(-1.f, 0.f, 0.f));  // texture space starts at x = 1
  EXPECT_EQ(texture_st(t, tp), Vec2(0.5f + 3.f, -1.f + 2.f));
}

}  // namespace
}  // namespace tessera
