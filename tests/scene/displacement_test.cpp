// plymesh displacement (pbrt-v4 "texture displacement", "edgelength"):
// refinement to the world-space edge length, displacement along the normals,
// recomputed normals.
#include <gtest/gtest.h>

#include <fstream>

#include "scene/displacement.h"
#include "scene_test_helpers.h"

namespace tessera {
namespace {

using test::load_error;
using test::load_world;
using test::TempDir;

// A 4 x 4 square in z = 0 with uv, normals +z, as an ASCII PLY.
const char* kSquarePly =
    "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\n"
    "property float u\nproperty float v\nelement face 2\nproperty list uchar int vertex_indices\nend_header\n"
    "0 0 0 0 0\n4 0 0 1 0\n4 4 0 1 1\n0 4 0 0 1\n3 0 1 2\n3 0 2 3\n";

TEST(Displacement, RefinesToTheEdgeLengthAndMovesAlongTheNormal) {
  TempDir dir;
  dir.write("sq.ply", kSquarePly);
  SceneDesc s = load_world("Texture \"d\" \"float\" \"constant\" \"float value\" 0.5\n"
                           "Shape \"plymesh\" \"string filename\" \"sq.ply\" \"texture displacement\" \"d\" "
                           "\"float edgelength\" 1\n",
                           dir.path());
  ASSERT_EQ(s.meshes.size(), 1u);
  const MeshDesc& m = s.meshes[0];
  EXPECT_GE(m.indices.size() / 3, 32u);  // 4 x 4 with edges < 1: at least 2 x 16 triangles
  for (size_t t = 0; t < m.indices.size(); t += 3)
    for (int k = 0; k < 3; ++k) EXPECT_LT(glm::length(m.p[m.indices[t + k]] - m.p[m.indices[t + (k + 1) % 3]]), 1.f);
  ASSERT_EQ(m.n.size(), m.p.size());
  for (size_t v = 0; v < m.p.size(); ++v) {
    EXPECT_NEAR(m.p[v].z, 0.5f, 1e-6f);  // the face normal is +z: displaced by 0.5 along it
    EXPECT_NEAR(m.n[v].z, 1.f, 1e-6f);
  }
}

TEST(Displacement, EdgeLengthIsMeasuredInWorldSpace) {
  TempDir dir;
  dir.write("sq.ply", kSquarePly);
  auto triangles = [&](const std::string& transform) {
    SceneDesc s = load_world(transform + "Texture \"d\" \"float\" \"constant\" \"float value\" 0\n"
                             "Shape \"plymesh\" \"string filename\" \"sq.ply\" \"texture displacement\" \"d\"\n",
                             dir.path());
    return s.meshes[0].indices.size() / 3;
  };
  EXPECT_GT(triangles("Scale 4 4 4\n"), 8 * triangles(""));
}

TEST(Displacement, TexturedHeightsAndErrors) {
  TempDir dir;
  dir.write("sq.ply", kSquarePly);
  // A checkerboard of heights 0 and 1 (2 x 2 checks over the uv square).
  SceneDesc s = load_world("Texture \"d\" \"float\" \"checkerboard\" \"float uscale\" 2 \"float vscale\" 2 "
                           "\"float tex1\" 0 \"float tex2\" 1\n"
                           "Shape \"plymesh\" \"string filename\" \"sq.ply\" \"texture displacement\" \"d\" "
                           "\"float edgelength\" 0.5\n",
                           dir.path());
  size_t low = 0, high = 0;
  for (const Vec3& p : s.meshes[0].p) {
    low += p.z == 0.f;
    high += p.z == 1.f;
  }
  EXPECT_GT(low, 10u);
  EXPECT_GT(high, 10u);
  EXPECT_EQ(low + high, s.meshes[0].p.size());
  // No uv: pbrt-v4 refuses too.
  dir.write("nouv.ply", "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
                        "element face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n");
  std::string e = load_error("WorldBegin\nTexture \"d\" \"float\" \"constant\"\n"
                             "Shape \"plymesh\" \"string filename\" \"nouv.ply\" \"texture displacement\" \"d\"\n",
                             dir.path());
  EXPECT_NE(e.find("bad.pbrt:3: plymesh 'nouv.ply': displacement: the mesh has no uv"), std::string::npos) << e;
  e = load_error("WorldBegin\nShape \"plymesh\" \"string filename\" \"sq.ply\" \"texture displacement\" \"nope\"\n", dir.path());
  EXPECT_NE(e.find("bad.pbrt:2: unknown float texture \"nope\""), std::string::npos) << e;
  e = load_error("WorldBegin\nTexture \"d\" \"float\" \"constant\"\nShape \"plymesh\" \"string filename\" \"sq.ply\" "
                 "\"texture displacement\" \"d\" \"float edgelength\" 1e-9\n",
                 dir.path());
  EXPECT_NE(e.find("would make more than"), std::string::npos) << e;
}

}  // namespace
}  // namespace tessera
