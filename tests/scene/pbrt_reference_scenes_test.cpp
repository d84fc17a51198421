// The scenes pbrt-v4 rendered for us (shared/pbrt-reference, copied into
// tests/data so the suite never depends on a folder outside the repository) must load.
#include "scene_test_helpers.h"

namespace tessera {
namespace {

std::string reference_dir() { return std::string(TESSERA_SOURCE_DIR) + "/tests/data"; }

size_t triangle_count(const SceneDesc& s) {
  size_t n = 0;
  for (const MeshDesc& m : s.meshes) n += m.indices.size() / 3;
  return n;
}

TEST(PbrtReferenceScenes, CornellBox) {
  const std::string path = reference_dir() + "/cornell-box-128.pbrt";
  SceneDesc s = load_pbrt_file(path);
  EXPECT_TRUE(s.warnings.empty()) << s.warnings.front();
  EXPECT_EQ(s.meshes.size(), 18u);
  EXPECT_EQ(triangle_count(s), 36u);
  EXPECT_EQ(s.materials.size(), 5u);  // default + 3 named + light's black diffuse
  ASSERT_EQ(s.area_lights.size(), 1u);
  EXPECT_VEC3_NEAR(s.area_lights[0].L, Vec3(17, 12, 4), 1e-6f);
  EXPECT_EQ(s.meshes.back().area_light, 0);
  EXPECT_TRUE(s.lights.empty());
  EXPECT_EQ(s.film.xres, 128);
  EXPECT_EQ(s.spp, 64);
  EXPECT_EQ(s.max_depth, 8);
  EXPECT_LT(glm::determinant(s.camera.world_from_camera), 0.f);
  // Render space: the camera at the origin, which is (278, 273, -800) in the file's world.
  EXPECT_VEC3_NEAR(Vec3(s.camera.world_from_camera * Vec4(0, 0, 0, 1)), Vec3(0.f), 1e-3f);
  EXPECT_VEC3_NEAR(Vec3(s.render_origin), Vec3(278, 273, -800), 1e-3f);
  // The light faces down into the box.
  EXPECT_LT(test::geometric_normal(s.meshes.back(), 0).y, -0.99f);
}

TEST(PbrtReferenceScenes, Materials) {
  const std::string path = reference_dir() + "/materials.pbrt";
  SceneDesc s = load_pbrt_file(path);
  EXPECT_TRUE(s.warnings.empty()) << s.warnings.front();
  EXPECT_EQ(s.meshes.size(), 6u);
  EXPECT_EQ(s.lights.size(), 1u);
  EXPECT_EQ(s.lights[0].type, LightType::Infinite);
  EXPECT_EQ(s.area_lights.size(), 1u);
  EXPECT_EQ(s.materials.size(), 7u);
  EXPECT_EQ(s.textures.size(), 1u);
  EXPECT_EQ(triangle_count(s), 4u + 4u * (2u * 64u * 128u - 2u * 128u));
  EXPECT_EQ(s.materials[s.meshes[2].material].type, MaterialType::Conductor);
  EXPECT_EQ(s.materials[s.meshes[5].material].type, MaterialType::CoatedDiffuse);
}

}  // namespace
}  // namespace tessera
