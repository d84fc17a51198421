// pbrt-v4's texture mappings and procedural texture classes through the
// loader: where each reads its coordinates (the CTM at the Texture
// directive), pbrt-v4's parameter names and defaults, and clear errors.
#include <gtest/gtest.h>

#include "kernels/procedural_texture.h"
#include "kernels/texture_eval.h"
#include "scene/displacement.h"
#include "scene_test_helpers.h"

namespace tessera {
namespace {

using test::kTriangle;
using test::load_error;
using test::load_world;

Float eval_at(const SceneDesc& s, int32_t texture, Vec3 p, Vec3 n = Vec3(0.f, 0.f, 1.f), Vec2 uv = Vec2(0.f)) {
  return HostTextures(s).eval(TextureSlot{texture, Rgb(0.f)}, p, n, uv);
}

TEST(PbrtTextureClasses, ThreeDimensionalTexturesFollowTheirTransformation) {
  SceneDesc s = load_world(
      "AttributeBegin\nTranslate 3 0 0\nScale 2 2 2\n"
      "Texture \"f\" \"float\" \"fbm\" \"integer octaves\" 5 \"float roughness\" 0.6\n"
      "Texture \"w\" \"float\" \"wrinkled\"\n"
      "Texture \"v\" \"float\" \"windy\"\n"
      "AttributeEnd\n" + std::string(kTriangle));
  ASSERT_EQ(s.textures.size(), 3u);
  EXPECT_TRUE(s.warnings.empty()) << s.warnings[0];
  // Render point (3 + 2 x) maps to texture point x.
  const Vec3 q(0.3f, 0.7f, 1.1f), p = Vec3(3.f, 0.f, 0.f) + 2.f * q;
  EXPECT_NEAR(eval_at(s, 0, p), fbm_noise(q, 0.6f, 5), 1e-5f);
  EXPECT_NEAR(eval_at(s, 1, p), turbulence_noise(q, 0.5f, 8), 1e-5f);  // pbrt-v4's defaults: 8 octaves, 0.5
  EXPECT_NEAR(eval_at(s, 2, p), windy_value(q), 1e-5f);
}

TEST(PbrtTextureClasses, MarbleIsASpectrumTextureWithPbrtV4sDefaults) {
  SceneDesc s = load_world("Texture \"m\" \"spectrum\" \"marble\" \"float scale\" 2.5 \"float variation\" 0.5\n"
                           "Texture \"d\" \"spectrum\" \"marble\"\n" + std::string(kTriangle));
  const Vec3 p(0.3f, 0.7f, 1.1f);
  SceneView view;
  view.textures = s.textures.data();
  const TexturePoint tp{p, Vec3(0.f, 0.f, 1.f), Vec2(0.f)};
  EXPECT_EQ(eval_texture(view, 0, tp), marble_value(2.5f * p, 0.5f, 0.5f, 8));
  EXPECT_EQ(eval_texture(view, 1, tp), marble_value(p, 0.2f, 0.5f, 8));
}

TEST(PbrtTextureClasses, ThreeDimensionalCheckerboardCellsAreUnitCubes) {
  SceneDesc s = load_world("AttributeBegin\nScale 0.5 0.5 0.5\n"
                           "Texture \"c\" \"float\" \"checkerboard\" \"integer dimension\" 3 \"float tex1\" 2 "
                           "\"float tex2\" 7\nAttributeEnd\n" + std::string(kTriangle));
  EXPECT_EQ(eval_at(s, 0, Vec3(0.25f, 0.25f, 0.25f)), 2.f);
  EXPECT_EQ(eval_at(s, 0, Vec3(0.75f, 0.25f, 0.25f)), 7.f);   // one cell along x (cells 0.5 wide)
  EXPECT_EQ(eval_at(s, 0, Vec3(0.75f, 0.75f, 0.25f)), 2.f);   // two cells
  EXPECT_EQ(eval_at(s, 0, Vec3(0.75f, 0.75f, -0.25f)), 7.f);  // three
  const Float at_nan = eval_at(s, 0, Vec3(NAN, 0.f, 0.f));
  EXPECT_TRUE(at_nan == 2.f || at_nan == 7.f) << at_nan;
  // Parity per axis: cells 9000001 and 9000000 differ (their sum would round to even in float).
  SceneDesc unit = load_world("Texture \"c\" \"float\" \"checkerboard\" \"integer dimension\" 3 \"float tex1\" 2 "
                              "\"float tex2\" 7\n" + std::string(kTriangle));
  EXPECT_EQ(eval_at(unit, 0, Vec3(9000001.f, 9000000.f, 0.5f)), 7.f);
  EXPECT_EQ(eval_at(unit, 0, Vec3(9000001.f, 9000001.f, 0.5f)), 2.f);
}

TEST(PbrtTextureClasses, SphericalCylindricalAndPlanarMappings) {
  // bilerp with v10 = v11 = 1 reads s; with v01 = v11 = 1 it reads t.
  SceneDesc s = load_world(
      "AttributeBegin\nTranslate 0 0 5\n"
      "Texture \"sph\" \"float\" \"bilerp\" \"string mapping\" \"spherical\" \"float v10\" 1 \"float v11\" 1 "
      "\"float v01\" 0\n"
      "Texture \"cyl\" \"float\" \"bilerp\" \"string mapping\" \"cylindrical\" \"float v10\" 0 \"float v11\" 1 "
      "\"float v01\" 1\n"
      "Texture \"pla\" \"float\" \"bilerp\" \"string mapping\" \"planar\" \"vector3 v1\" [ 0 0 2 ] "
      "\"float udelta\" 0.25 \"float v10\" 1 \"float v11\" 1 \"float v01\" 0\n"
      "AttributeEnd\n" + std::string(kTriangle));
  EXPECT_TRUE(s.warnings.empty()) << s.warnings[0];
  EXPECT_NEAR(eval_at(s, 0, Vec3(0.f, 0.f, 9.f)), 0.f, 1e-6f);   // above the texture origin (0, 0, 5): theta 0
  EXPECT_NEAR(eval_at(s, 0, Vec3(1.f, 1.f, 5.f)), 0.5f, 1e-6f);  // level with it: theta pi / 2
  EXPECT_NEAR(eval_at(s, 0, Vec3(0.f, 0.f, 1.f)), 1.f, 1e-6f);
  EXPECT_NEAR(eval_at(s, 1, Vec3(4.f, 0.f, 3.5f)), -1.5f, 1e-6f);  // t = z in texture space
  EXPECT_NEAR(eval_at(s, 2, Vec3(7.f, 7.f, 5.5f)), 0.25f + 2.f * 0.5f, 1e-6f);  // s = udelta + p . v1
}

// pbrt-v4's dots texture draws its "outside" value in the dots (its
// constructor takes the two in the other order than Create passes them).
TEST(PbrtTextureClasses, DotsDrawWhatPbrtV4Draws) {
  SceneDesc s = load_world("Texture \"d\" \"float\" \"dots\" \"float inside\" 2 \"float outside\" 3\n" +
                           std::string(kTriangle));
  EXPECT_EQ(eval_at(s, 0, Vec3(0.f), Vec3(0.f, 0.f, 1.f), Vec2(0.f, 1.f)), 3.f);  // in a dot
  EXPECT_EQ(eval_at(s, 0, Vec3(0.f), Vec3(0.f, 0.f, 1.f), Vec2(0.f, 0.f)), 2.f);  // no dot in this cell
}

TEST(PbrtTextureClasses, DirectionMixWeighsTex1ByTheNormalAlongDir) {
  // dir (0, 0, 1) rotated 90 degrees about x becomes (0, -1, 0) in render space.
  SceneDesc s = load_world("AttributeBegin\nRotate 90 1 0 0\n"
                           "Texture \"m\" \"float\" \"directionmix\" \"float tex1\" 10 \"float tex2\" 20 "
                           "\"vector3 dir\" [ 0 0 3 ]\nAttributeEnd\n" + std::string(kTriangle));
  EXPECT_NEAR(eval_at(s, 0, Vec3(0.f), Vec3(0.f, 1.f, 0.f)), 10.f, 1e-4f);
  EXPECT_NEAR(eval_at(s, 0, Vec3(0.f), Vec3(0.f, 0.f, 1.f)), 20.f, 1e-4f);
  EXPECT_NEAR(eval_at(s, 0, Vec3(0.f), Vec3(0.f, -0.6f, 0.8f)), 0.6f * 10.f + 0.4f * 20.f, 1e-4f);
}

TEST(PbrtTextureClasses, ClearErrorsForWhatPbrtV4Refuses) {
  const std::string w = "WorldBegin\n";
  EXPECT_NE(load_error(w + "Texture \"n\" \"spectrum\" \"fbm\"\n").find("bad.pbrt:2: \"fbm\" is not a spectrum texture"),
            std::string::npos);
  EXPECT_NE(load_error(w + "Texture \"n\" \"float\" \"marble\"\n").find("bad.pbrt:2: \"marble\" is not a float texture"),
            std::string::npos);
  EXPECT_NE(load_error(w + "Texture \"c\" \"float\" \"checkerboard\" \"integer dimension\" 4\n")
                .find("bad.pbrt:2: 4 dimensional checkerboard"),
            std::string::npos);
  EXPECT_NE(load_error(w + "Texture \"n\" \"float\" \"wrinkled\" \"integer octaves\" -1\n").find("bad.pbrt:2: \"octaves\""),
            std::string::npos);
  EXPECT_NE(load_error(w + "Scale 0 1 1\nTexture \"n\" \"float\" \"fbm\"\n").find("bad.pbrt:3: the texture's transformation is singular"),
            std::string::npos);
  EXPECT_NE(load_error(w + "Texture \"m\" \"float\" \"directionmix\" \"vector3 dir\" [ 0 0 0 ]\n").find("bad.pbrt:2: directionmix"),
            std::string::npos);
  // A uv texture needs no inverse: a singular CTM is no error for it.
  EXPECT_EQ(load_error(w + "Scale 0 1 1\nTexture \"n\" \"float\" \"bilerp\"\n").find("singular"), std::string::npos);
}

TEST(PbrtTextureClasses, HugeOctavesAreClampedAndUnknownMappingsWarn) {
  SceneDesc s = load_world("Texture \"n\" \"float\" \"fbm\" \"integer octaves\" 1000\n"
                           "Texture \"b\" \"float\" \"bilerp\" \"string mapping\" \"cubic\"\n" + std::string(kTriangle));
  EXPECT_EQ(s.textures[0].octaves, 32);
  EXPECT_EQ(s.textures[1].mapping, TextureMapping::UV);
  ASSERT_EQ(s.warnings.size(), 2u);
  EXPECT_NE(s.warnings[0].find("test.pbrt:2: \"octaves\" 1000 clamped to 32"), std::string::npos);
  EXPECT_NE(s.warnings[1].find("test.pbrt:3: 2D texture mapping \"cubic\" unknown"), std::string::npos);
}

}  // namespace
}  // namespace tessera
