// LightSource and AreaLightSource.
#include <ImfRgbaFile.h>

#include <vector>

#include "scene_test_helpers.h"

namespace tessera {
namespace {

using test::kTriangle;
using test::load_world;

TEST(PbrtLights, AreaLightAppliesToShapesInBlock) {
  SceneDesc s = load_world(std::string("AttributeBegin\nAreaLightSource \"diffuse\" \"rgb L\" [ 2 3 4 ] \"float scale\" 0.5"
                                       " \"bool twosided\" true\n") + kTriangle + kTriangle + "AttributeEnd\n" + kTriangle);
  ASSERT_EQ(s.area_lights.size(), 1u);
  EXPECT_VEC3_NEAR(s.area_lights[0].L, Vec3(1.f, 1.5f, 2.f), 1e-6f);
  EXPECT_TRUE(s.area_lights[0].two_sided);
  EXPECT_EQ(s.meshes[0].area_light, 0);
  EXPECT_EQ(s.meshes[1].area_light, 0);
  EXPECT_EQ(s.meshes[2].area_light, -1);
}

TEST(PbrtLights, PointLightWithPower) {
  SceneDesc s = load_world("Translate 1 0 0\nLightSource \"point\" \"rgb I\" [ 1 2 3 ] \"point3 from\" [ 0 1 0 ] \"float scale\" 2\n"
                           "LightSource \"point\" \"float power\" 100\n");
  ASSERT_EQ(s.lights.size(), 2u);
  EXPECT_EQ(s.lights[0].type, LightType::Point);
  EXPECT_VEC3_NEAR(s.lights[0].L, Vec3(2, 4, 6), 1e-6f);
  EXPECT_VEC3_NEAR(s.lights[0].position, Vec3(1, 1, 0), 1e-6f);
  EXPECT_NEAR(s.lights[1].L.y * 4.f * kPi, 100.f, 1e-3f);
}

TEST(PbrtLights, SpotLightCone) {
  SceneDesc s = load_world("Rotate 90 0 1 0\nLightSource \"spot\" \"point3 from\" [ 0 0 0 ] \"point3 to\" [ 0 0 1 ]"
                           " \"float coneangle\" 40 \"float conedeltaangle\" 10\n");
  const Light& l = s.lights[0];
  EXPECT_EQ(l.type, LightType::Spot);
  EXPECT_VEC3_NEAR(l.direction, Vec3(1, 0, 0), 1e-6f);
  EXPECT_NEAR(l.cos_falloff_end, std::cos(40.f * kPi / 180.f), 1e-6f);
  EXPECT_NEAR(l.cos_falloff_start, std::cos(30.f * kPi / 180.f), 1e-6f);
}

TEST(PbrtLights, DistantLightPointsTowardsLight) {
  SceneDesc s = load_world("LightSource \"distant\" \"point3 from\" [ 0 10 0 ] \"point3 to\" [ 0 0 0 ] \"blackbody L\" 6500\n");
  const Light& l = s.lights[0];
  EXPECT_EQ(l.type, LightType::Distant);
  EXPECT_VEC3_NEAR(l.direction, Vec3(0, 1, 0), 1e-6f);
  // 6500 K is close to D65 white and normalised to luminance 1.
  EXPECT_NEAR(0.2126f * l.L.x + 0.7152f * l.L.y + 0.0722f * l.L.z, 1.f, 0.02f);
  EXPECT_NEAR(l.L.x / l.L.z, 1.f, 0.1f);
}

TEST(PbrtLights, InfiniteConstantAndImage) {
  test::TempDir dir;
  Imf::Rgba pixels[4 * 4];
  for (Imf::Rgba& p : pixels) p = Imf::Rgba(1.f, 1.f, 1.f, 1.f);
  {
    Imf::RgbaOutputFile out(dir.file("sky.exr").c_str(), 4, 4, Imf::WRITE_RGBA);
    out.setFrameBuffer(pixels, 1, 4);
    out.writePixels(4);
  }
  SceneDesc s = load_world("LightSource \"infinite\" \"rgb L\" [ 0.25 0.3 0.4 ]\nRotate 90 0 0 1\n"
                           "LightSource \"infinite\" \"string filename\" \"sky.exr\" \"float scale\" 3\n",
                           dir.path());
  ASSERT_EQ(s.lights.size(), 2u);
  EXPECT_VEC3_NEAR(s.lights[0].L, Vec3(0.25f, 0.3f, 0.4f), 1e-6f);
  EXPECT_EQ(s.lights[0].image, -1);
  EXPECT_EQ(s.lights[1].image, 0);
  EXPECT_VEC3_NEAR(s.lights[1].L, Vec3(3.f), 1e-6f);
  EXPECT_VEC3_NEAR(s.lights[1].light_from_world * Vec3(0, 1, 0), Vec3(1, 0, 0), 1e-6f);
}

TEST(PbrtLights, InfiniteIlluminanceScalesAsPbrtV4) {
  test::TempDir dir;
  constexpr int kRes = 64;
  std::vector<Imf::Rgba> pixels(kRes * kRes, Imf::Rgba(0.5f, 0.5f, 0.5f, 1.f));
  {
    Imf::RgbaOutputFile out(dir.file("sky.exr").c_str(), kRes, kRes, Imf::WRITE_RGBA);
    out.setFrameBuffer(pixels.data(), 1, kRes);
    out.writePixels(kRes);
  }
  SceneDesc s = load_world("LightSource \"infinite\" \"rgb L\" [ 2 2 2 ] \"float illuminance\" 6\n"
                           "LightSource \"infinite\" \"string filename\" \"sky.exr\" \"float illuminance\" 6\n",
                           dir.path());
  ASSERT_EQ(s.lights.size(), 2u);
  EXPECT_TRUE(s.warnings.empty()) << s.warnings[0];
  // A constant L: scaled by E / pi (an RGB L keeps its own magnitude too, as in pbrt-v4).
  EXPECT_VEC3_NEAR(s.lights[0].L, Vec3(2.f * 6.f / kPi), 1e-5f);
  // An image: by E over pbrt-v4's upper-hemisphere sum, which for a uniform
  // image is its value times about pi / 2 (pbrt-v4 weighs each pixel 2 pi / N).
  EXPECT_NEAR(s.lights[1].L.x * 0.5f, 6.f / (kPi / 2.f), 0.01f * 6.f / (kPi / 2.f));
}

TEST(PbrtLights, UnsupportedLightsWarn) {
  SceneDesc s = load_world(std::string("LightSource \"sunsky\" \"float turbidity\" 3\n") + kTriangle);
  EXPECT_TRUE(s.lights.empty());
  ASSERT_EQ(s.warnings.size(), 1u);
  EXPECT_NE(s.warnings[0].find("test.pbrt:2"), std::string::npos);
}

}  // namespace
}  // namespace tessera
