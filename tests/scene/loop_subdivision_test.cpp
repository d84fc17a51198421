// Loop subdivision ("loopsubdiv"): counts, the properties Loop's rules
// guarantee, pbrt-v4's normal convention, and errors for meshes the rules
// are not defined on.
#include <gtest/gtest.h>

#include <cmath>

#include "scene/loop_subdivision.h"
#include "scene/scene_desc.h"
#include "scene_test_helpers.h"

namespace tessera {
namespace {

using test::load_error;
using test::load_world;

// A regular tetrahedron, every face counter-clockwise seen from outside.
const std::vector<Vec3> kTetP = {{1, 1, 1}, {1, -1, -1}, {-1, 1, -1}, {-1, -1, 1}};
const std::vector<uint32_t> kTetI = {0, 1, 2, 0, 3, 1, 0, 2, 3, 1, 3, 2};

std::string subdivide_error(const std::vector<Vec3>& p, const std::vector<uint32_t>& i, int levels) {
  try {
    loop_subdivide(p, i, levels);
  } catch (const SceneError& e) {
    return e.what();
  }
  return "";
}

TEST(LoopSubdivision, EachLevelQuadruplesTheTrianglesAndAddsAVertexPerEdge) {
  for (int levels : {0, 1, 2, 3}) {
    SubdividedMesh m = loop_subdivide(kTetP, kTetI, levels);
    const size_t faces = 4u << (2 * levels);
    EXPECT_EQ(m.indices.size(), 3 * faces);
    // A closed triangle mesh: V - E + F = 2 with E = 3F/2.
    EXPECT_EQ(m.p.size(), 2 + faces / 2);
    EXPECT_EQ(m.n.size(), m.p.size());
    for (uint32_t i : m.indices) EXPECT_LT(i, m.p.size());
  }
}

TEST(LoopSubdivision, SymmetricClosedMeshStaysCentredAndNormalsFollowPbrtsConvention) {
  SubdividedMesh m = loop_subdivide(kTetP, kTetI, 3);
  // The four original vertices' limit points are equidistant from the centre
  // (the rules are symmetric), and closer in than the corners (smoothing).
  const Float r0 = glm::length(m.p[0]);
  for (int v = 1; v < 4; ++v) EXPECT_NEAR(glm::length(m.p[v]), r0, 1e-5f);
  EXPECT_LT(r0, glm::length(kTetP[0]) * 0.9f);
  Vec3 centre(0.f);
  for (const Vec3& p : m.p) centre += p;
  centre /= static_cast<Float>(m.p.size());
  EXPECT_LT(glm::length(centre), 1e-5f);
  // pbrt-v4's S x T points against the side the counter-clockwise winding
  // faces: inward here, for every vertex.
  for (size_t v = 0; v < m.p.size(); ++v) {
    const Float cos_out = glm::dot(glm::normalize(m.n[v]), glm::normalize(m.p[v]));
    EXPECT_LT(cos_out, -0.5f) << v;
  }
}

TEST(LoopSubdivision, PlanarMeshesStayInTheirPlaneWithStraightBoundaries) {
  // A 3x3 grid of quads in z = 2, split into triangles: an open mesh with
  // boundary vertices of valence 2..4 and interior vertices of valence 6.
  std::vector<Vec3> p;
  std::vector<uint32_t> idx;
  for (int y = 0; y <= 3; ++y)
    for (int x = 0; x <= 3; ++x) p.emplace_back(static_cast<Float>(x), static_cast<Float>(y), 2.f);
  for (uint32_t y = 0; y < 3; ++y)
    for (uint32_t x = 0; x < 3; ++x) {
      const uint32_t a = y * 4 + x, b = a + 1, c = a + 5, d = a + 4;
      idx.insert(idx.end(), {a, b, c, a, c, d});
    }
  SubdividedMesh m = loop_subdivide(p, idx, 2);
  for (size_t v = 0; v < m.p.size(); ++v) {
    EXPECT_NEAR(m.p[v].z, 2.f, 1e-6f);
    // Inside the square, and boundary points on its edges stay there.
    EXPECT_GE(m.p[v].x, -1e-6f);
    EXPECT_LE(m.p[v].x, 3.f + 1e-6f);
    const Vec3 n = m.n[v];
    ASSERT_GT(glm::length(n), 0.f) << v;
    EXPECT_NEAR(std::abs(glm::normalize(n).z), 1.f, 1e-5f) << v;
  }
  // The boundary is a cubic B-spline of the boundary polygon: it rounds the
  // corners but keeps the straight middle of each side. On the bottom side
  // (y = 0) that is x in [1, 2], split in quarters at two levels.
  size_t on_bottom = 0;
  for (const Vec3& q : m.p) {
    EXPECT_GE(q.y, -1e-6f);
    if (std::abs(q.y) < 1e-6f) {
      ++on_bottom;
      EXPECT_GE(q.x, 1.f - 1e-6f);
      EXPECT_LE(q.x, 2.f + 1e-6f);
    }
  }
  EXPECT_EQ(on_bottom, 5u);
}

TEST(LoopSubdivision, MeshesTheRulesAreNotDefinedOnAreErrors) {
  // Three triangles on one edge.
  const std::vector<Vec3> p = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}};
  EXPECT_NE(subdivide_error(p, {0, 1, 2, 1, 0, 3, 0, 1, 4}, 1).find("more than two triangles"), std::string::npos);
  // Neighbours wound in opposite directions.
  EXPECT_NE(subdivide_error(p, {0, 1, 2, 0, 1, 3}, 1).find("opposite directions"), std::string::npos);
  // Two fans meeting at one vertex (a bow tie).
  const std::vector<Vec3> bow = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {-1, 0, 0}, {-1, -1, 0}};
  EXPECT_NE(subdivide_error(bow, {0, 1, 2, 0, 3, 4}, 1).find("one fan"), std::string::npos);
  EXPECT_NE(subdivide_error(p, {0, 0, 1}, 1).find("repeats a vertex"), std::string::npos);
  EXPECT_NE(subdivide_error(kTetP, kTetI, 14).find("more than"), std::string::npos);
  // A single triangle asking for 4^30 faces is refused before any work.
  EXPECT_NE(subdivide_error({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}, {0, 1, 2}, 30).find("more than"), std::string::npos);
  EXPECT_NE(subdivide_error({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}, {0, 1, 2}, 14).find("more than"), std::string::npos);
}

TEST(LoopSubdivision, SceneShapeSubdividesWithPbrtsDefaultsAndReportsErrorsWithLocation) {
  std::string tet = "Shape \"loopsubdiv\" \"point3 P\" [ 1 1 1  1 -1 -1  -1 1 -1  -1 -1 1 ] "
                    "\"integer indices\" [ 0 1 2  0 3 1  0 2 3  1 3 2 ]";
  SceneDesc s = load_world(tet + "\n");
  ASSERT_EQ(s.meshes.size(), 1u);
  EXPECT_EQ(s.meshes[0].indices.size(), 3u * 4 * 64);  // levels defaults to 3
  EXPECT_EQ(s.meshes[0].n.size(), s.meshes[0].p.size());
  SceneDesc one = load_world(tet + " \"integer levels\" 1\n");
  EXPECT_EQ(one.meshes[0].indices.size(), 3u * 16);
  std::string e = load_error("WorldBegin\n\nShape \"loopsubdiv\" \"point3 P\" [ 0 0 0 1 0 0 0 1 0 0 -1 0 ] "
                             "\"integer indices\" [ 0 1 2 0 1 3 ]\n");
  EXPECT_NE(e.find("bad.pbrt:3: loopsubdiv: two neighbouring triangles"), std::string::npos) << e;
  e = load_error("WorldBegin\nShape \"loopsubdiv\" \"point3 P\" [ 0 0 0 1 0 0 0 1 0 ] \"integer indices\" [ 0 1 5 ]\n");
  EXPECT_NE(e.find("bad.pbrt:2: loopsubdiv index 5 out of range"), std::string::npos) << e;
}

}  // namespace
}  // namespace tessera
