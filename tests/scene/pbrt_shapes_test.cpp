// Shapes: trianglemesh, bilinearmesh, sphere, disk, cylinder, plymesh.
#include "scene_test_helpers.h"

namespace tessera {
namespace {

using test::load_world;

TEST(PbrtShapes, TriangleMeshWithUvAndNormals) {
  SceneDesc s = load_world(
      "Shape \"trianglemesh\" \"point3 P\" [ 0 0 0 1 0 0 1 1 0 0 1 0 ] \"integer indices\" [ 0 1 2 0 2 3 ]\n"
      "  \"point2 uv\" [ 0 0 1 0 1 1 0 1 ] \"normal N\" [ 0 0 1 0 0 1 0 0 1 0 0 1 ]\n"
      "Shape \"trianglemesh\" \"point3 P\" [ 0 0 0 1 0 0 0 1 0 ]\n");
  ASSERT_EQ(s.meshes.size(), 2u);
  EXPECT_EQ(s.meshes[0].indices.size(), 6u);
  ASSERT_EQ(s.meshes[0].uv.size(), 4u);
  EXPECT_FLOAT_EQ(s.meshes[0].uv[2].x, 1.f);
  ASSERT_EQ(s.meshes[0].n.size(), 4u);
  EXPECT_EQ(s.meshes[0].where, "test.pbrt:2");
  EXPECT_EQ(s.meshes[1].indices, (std::vector<uint32_t>{0, 1, 2}));  // implicit for 3 vertices
}

TEST(PbrtShapes, NormalsUseInverseTranspose) {
  SceneDesc s = load_world(
      "Scale 1 4 1\nShape \"trianglemesh\" \"point3 P\" [ 0 0 0 1 0 0 0 1 0 ] \"normal N\" [ 0.7071 0.7071 0 "
      "0.7071 0.7071 0 0.7071 0.7071 0 ]\n");
  Vec3 expected = glm::normalize(Vec3(1.f, 0.25f, 0.f));
  EXPECT_VEC3_NEAR(s.meshes[0].n[0], expected, 1e-4f);
}

TEST(PbrtShapes, SphereIsOutwardWithPbrtUvAndArea) {
  SceneDesc s = load_world("Translate 1 2 3\nShape \"sphere\" \"float radius\" 2\n");
  ASSERT_EQ(s.meshes.size(), 1u);
  const MeshDesc& m = s.meshes[0];
  const Vec3 centre(1, 2, 3);
  for (size_t t = 0; t < m.indices.size() / 3; ++t) {
    Vec3 c = (m.p[m.indices[3 * t]] + m.p[m.indices[3 * t + 1]] + m.p[m.indices[3 * t + 2]]) / 3.f;
    ASSERT_GT(glm::dot(test::geometric_normal(m, t), c - centre), 0.f) << "triangle " << t;
  }
  for (size_t v = 0; v < m.p.size(); ++v) {
    Vec3 d = glm::normalize(m.p[v] - centre);
    ASSERT_GT(glm::dot(m.n[v], d), 0.999f);
    // pbrt: v = 1 - theta/pi with theta from +z; u = phi / 2pi.
    ASSERT_NEAR(m.uv[v].y, 1.f - std::acos(glm::clamp(d.z, -1.f, 1.f)) / kPi, 1e-3f);
  }
  double area = test::surface_area(m), exact = 4. * kPi * 4.;
  EXPECT_NEAR(area / exact, 1., 0.01);
  EXPECT_FALSE(m.flip_normals);
}

TEST(PbrtShapes, CylinderIsOutwardWithPbrtUvAndArea) {
  SceneDesc s = load_world("Shape \"cylinder\" \"float radius\" 2 \"float zmin\" -1 \"float zmax\" 3\n"
                           "Shape \"cylinder\" \"float phimax\" 90\n");
  ASSERT_EQ(s.meshes.size(), 2u);
  const MeshDesc& m = s.meshes[0];
  for (size_t t = 0; t < m.indices.size() / 3; ++t) {
    const Vec3 c = (m.p[m.indices[3 * t]] + m.p[m.indices[3 * t + 1]] + m.p[m.indices[3 * t + 2]]) / 3.f;
    ASSERT_GT(glm::dot(test::geometric_normal(m, t), Vec3(c.x, c.y, 0.f)), 0.f) << "triangle " << t;
  }
  for (size_t v = 0; v < m.p.size(); ++v) {
    ASSERT_NEAR(m.uv[v].y, (m.p[v].z + 1.f) / 4.f, 1e-5f);  // v along z from zmin
    ASSERT_NEAR(glm::length(Vec2(m.p[v].x, m.p[v].y)), 2.f, 1e-5f);
  }
  EXPECT_NEAR(test::surface_area(m) / (2. * kPi * 2. * 4.), 1., 0.01);
  // A quarter cylinder: phimax 90 degrees.
  EXPECT_NEAR(test::surface_area(s.meshes[1]) / (0.5 * kPi * 1. * 2.), 1., 0.01);
  EXPECT_TRUE(s.warnings.empty());
}

TEST(PbrtShapes, ReverseOrientationTurnsSphereInward) {
  SceneDesc s = load_world("ReverseOrientation\nShape \"sphere\"\n");
  const MeshDesc& m = s.meshes[0];
  EXPECT_TRUE(m.flip_normals);
  EXPECT_LT(glm::dot(test::geometric_normal(m, 10), m.p[m.indices[30]]), 0.f);
  EXPECT_LT(glm::dot(m.n[200], m.p[200]), 0.f);
}

TEST(PbrtShapes, PartialSpheresAreCutAsInPbrtV4) {
  // The upper hemisphere (zmin 0) of a half turn (phimax 180): a quarter of the area.
  SceneDesc s = load_world("Shape \"sphere\" \"float zmin\" 0 \"float phimax\" 180\n");
  ASSERT_EQ(s.meshes.size(), 1u);
  const MeshDesc& m = s.meshes[0];
  EXPECT_NEAR(test::surface_area(m) / kPi, 1., 0.01);  // 4 pi r^2 / 4
  for (size_t v = 0; v < m.p.size(); ++v) {
    ASSERT_GE(m.p[v].z, -1e-6f);
    ASSERT_GE(m.p[v].y, -1e-6f);  // phi in [0, pi]
    // v runs linearly in theta from zmin (0, theta = pi/2) to zmax (1, theta = 0).
    ASSERT_NEAR(m.uv[v].y, 1.f - std::acos(glm::clamp(m.p[v].z, -1.f, 1.f)) / (0.5f * kPi), 1e-3f);
  }
  EXPECT_TRUE(s.warnings.empty());
}

TEST(PbrtShapes, DiskFacesPlusZWithPbrtUv) {
  SceneDesc s = load_world("Shape \"disk\" \"float height\" 0.5 \"float radius\" 2 \"float innerradius\" 1\n");
  const MeshDesc& m = s.meshes[0];
  for (size_t t = 0; t < m.indices.size() / 3; ++t) ASSERT_GT(test::geometric_normal(m, t).z, 0.99f);
  for (size_t v = 0; v < m.p.size(); ++v) {
    ASSERT_FLOAT_EQ(m.p[v].z, 0.5f);
    float r = glm::length(Vec2(m.p[v]));
    ASSERT_NEAR(m.uv[v].y, (2.f - r) / 1.f, 1e-5f);
  }
  EXPECT_NEAR(test::surface_area(m) / (kPi * 3.), 1., 0.01);
  // A quarter disk (phimax 90): a quarter of the area, u = phi / phimax.
  s = load_world("Shape \"disk\" \"float phimax\" 90\n");
  EXPECT_NEAR(test::surface_area(s.meshes[0]) / (0.25 * kPi), 1., 0.01);
  for (const Vec3& p : s.meshes[0].p) ASSERT_TRUE(p.x >= -1e-6f && p.y >= -1e-6f);
  EXPECT_TRUE(s.warnings.empty());
  // Under a rotation the normal follows.
  s = load_world("Rotate 90 1 0 0\nShape \"disk\"\n");
  EXPECT_VEC3_NEAR(test::geometric_normal(s.meshes[0], 0), Vec3(0, -1, 0), 1e-5f);
}

TEST(PbrtShapes, BilinearMeshSplitsPatchesKeepingOrientation) {
  SceneDesc s = load_world(
      "Shape \"bilinearmesh\" \"point3 P\" [ 0 0 0  1 0 0  0 1 0  1 1 0 ] \"integer indices\" [ 0 1 2 3 ]"
      " \"point2 uv\" [ 0 0 1 0 0 1 1 1 ]\n");
  const MeshDesc& m = s.meshes[0];
  EXPECT_EQ(m.indices, (std::vector<uint32_t>{0, 1, 3, 0, 3, 2}));
  for (size_t t = 0; t < 2; ++t) EXPECT_VEC3_NEAR(test::geometric_normal(m, t), Vec3(0, 0, 1), 1e-6f);  // dpdu x dpdv
  EXPECT_NEAR(test::surface_area(m), 1., 1e-6);
  EXPECT_EQ(m.uv.size(), 4u);
}

TEST(PbrtShapes, UnsupportedShapeWarnsAndSkips) {
  // pbrt-v3's hyperboloid is not a pbrt-v4 shape.
  SceneDesc s = load_world(std::string("Shape \"hyperboloid\" \"point3 p1\" [ 0 0 0 ]\n") + test::kTriangle);
  EXPECT_EQ(s.meshes.size(), 1u);
  ASSERT_EQ(s.warnings.size(), 1u);
  EXPECT_NE(s.warnings[0].find("test.pbrt:2: unsupported shape \"hyperboloid\""), std::string::npos);
}

const char* kAsciiPly =
    "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\n"
    "property float nx\nproperty float ny\nproperty float nz\nproperty float u\nproperty float v\n"
    "element face 1\nproperty list uchar int vertex_indices\nend_header\n"
    "0 0 0 0 0 1 0 0\n1 0 0 0 0 1 1 0\n1 1 0 0 0 1 1 1\n0 1 0 0 0 1 0 1\n4 0 1 2 3\n";

TEST(PbrtShapes, AsciiPlyQuadIsTriangulated) {
  test::TempDir dir;
  dir.write("meshes/quad.ply", kAsciiPly);
  dir.write("scene.pbrt", "WorldBegin\nTranslate 0 0 5\nShape \"plymesh\" \"string filename\" \"meshes/quad.ply\"\n");
  SceneDesc s = load_pbrt_file(dir.file("scene.pbrt"));
  ASSERT_EQ(s.meshes.size(), 1u);
  const MeshDesc& m = s.meshes[0];
  EXPECT_EQ(m.indices.size(), 6u);
  EXPECT_EQ(m.n.size(), m.p.size());
  EXPECT_EQ(m.uv.size(), m.p.size());
  EXPECT_NEAR(test::surface_area(m), 1., 1e-6);
  for (const Vec3& p : m.p) EXPECT_FLOAT_EQ(p.z, 5.f);
  for (size_t v = 0; v < m.p.size(); ++v) EXPECT_VEC3_NEAR(Vec3(m.p[v].x, m.p[v].y, 0), Vec3(m.uv[v], 0), 1e-6f);
}

TEST(PbrtShapes, BinaryPlyLoads) {
  test::TempDir dir;
  // Little-endian binary: 3 float vertices, one int-list face.
  std::string header =
      "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
      "element face 1\nproperty list uchar int vertex_indices\nend_header\n";
  std::string body;
  const float verts[9] = {0, 0, 0, 2, 0, 0, 0, 2, 0};
  body.append(reinterpret_cast<const char*>(verts), sizeof(verts));
  body.push_back(3);
  const int32_t idx[3] = {0, 1, 2};
  body.append(reinterpret_cast<const char*>(idx), sizeof(idx));
  dir.write("tri.ply", header + body);
  SceneDesc s = load_world("Shape \"plymesh\" \"string filename\" \"tri.ply\"\n", dir.path());
  ASSERT_EQ(s.meshes.size(), 1u);
  EXPECT_EQ(s.meshes[0].indices.size(), 3u);
  EXPECT_NEAR(test::surface_area(s.meshes[0]), 2., 1e-6);
  EXPECT_TRUE(s.meshes[0].n.empty());
}

}  // namespace
}  // namespace tessera

namespace tessera {
namespace {

TEST(PbrtShapes, AlphaIsAFloatOrAFloatTexture) {
  SceneDesc s = test::load_world(std::string("Shape \"trianglemesh\" \"point3 P\" [ 0 0 0 1 0 0 0 1 0 ] \"float alpha\" 0.25\n") +
                                 test::kTriangle);
  ASSERT_EQ(s.meshes.size(), 2u);
  EXPECT_EQ(s.meshes[0].alpha.value.x, 0.25f);
  EXPECT_EQ(s.meshes[1].alpha.value.x, 1.f);
  s = test::load_world("Texture \"a\" \"float\" \"checkerboard\"\nShape \"trianglemesh\" \"point3 P\" [ 0 0 0 1 0 0 0 1 0 ] "
                       "\"texture alpha\" \"a\"\n");
  EXPECT_GE(s.meshes[0].alpha.texture, 0);
  EXPECT_NE(test::load_error("WorldBegin\nShape \"trianglemesh\" \"point3 P\" [ 0 0 0 1 0 0 0 1 0 ] \"float alpha\" 2\n")
                .find("bad.pbrt:2: shape \"alpha\" must be in [0, 1]"),
            std::string::npos);
  s = test::load_world("AreaLightSource \"diffuse\"\nShape \"trianglemesh\" \"point3 P\" [ 0 0 0 1 0 0 0 1 0 ] \"float alpha\" 0.5\n");
  bool warned = false;
  for (const std::string& w : s.warnings) warned |= w.find("cuts out its surface but not its emission") != std::string::npos;
  EXPECT_TRUE(warned);
}

}  // namespace
}  // namespace tessera
