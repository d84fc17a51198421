// pbrt-v4's "curve" shape (scene/curve_tessellation.h): the Bezier
// conversions, the tube's geometry and coverage, orientation and the errors.
#include "scene/curve_tessellation.h"

#include <cmath>

#include "scene_test_helpers.h"

namespace tessera {
namespace {

using test::load_world;

Vec3 cubic(const std::vector<Vec3>& b, size_t seg, Float u) {
  const Vec3* c = b.data() + 4 * seg;
  const Float v = 1.f - u;
  return v * v * v * c[0] + 3.f * v * v * u * c[1] + 3.f * v * u * u * c[2] + u * u * u * c[3];
}

TEST(CurveTessellation, BasesConvertToTheSameCurve) {
  const std::vector<Vec3> q = {{0, 0, 0}, {1, 2, 0}, {3, 2, 1}, {4, 0, 1}, {6, 1, 0}};
  // Quadratic Bezier (2 segments): B(1/2) = q0/4 + q1/2 + q2/4.
  CurveSegments quad = curve_segments(q, "bezier", 2, CurveType::Cylinder, {});
  ASSERT_EQ(quad.cps.size(), 8u);
  EXPECT_VEC3_NEAR(cubic(quad.cps, 0, 0.5f), 0.25f * q[0] + 0.5f * q[1] + 0.25f * q[2], 1e-5f);
  EXPECT_VEC3_NEAR(cubic(quad.cps, 1, 1.f), q[4], 1e-6f);
  // Cubic B-spline (2 spans): span ends are (q0 + 4 q1 + q2) / 6 and its successor; C1 at the join.
  CurveSegments bs = curve_segments(q, "bspline", 3, CurveType::Cylinder, {});
  ASSERT_EQ(bs.cps.size(), 8u);
  EXPECT_VEC3_NEAR(cubic(bs.cps, 0, 0.f), (q[0] + 4.f * q[1] + q[2]) / 6.f, 1e-5f);
  EXPECT_VEC3_NEAR(cubic(bs.cps, 0, 1.f), cubic(bs.cps, 1, 0.f), 1e-5f);
  EXPECT_VEC3_NEAR(bs.cps[3] - bs.cps[2], bs.cps[5] - bs.cps[4], 1e-5f);
  // Quadratic B-spline (3 spans): span 0 runs from mid(q0, q1) to mid(q1, q2) through q1/2 + ...
  CurveSegments qb = curve_segments(q, "bspline", 2, CurveType::Cylinder, {});
  ASSERT_EQ(qb.cps.size(), 12u);
  EXPECT_VEC3_NEAR(cubic(qb.cps, 0, 0.f), 0.5f * (q[0] + q[1]), 1e-5f);
  EXPECT_VEC3_NEAR(cubic(qb.cps, 0, 0.5f), 0.125f * q[0] + 0.75f * q[1] + 0.125f * q[2], 1e-5f);
}

// A straight tube: every vertex at the same distance from the axis, faces
// outward, and the silhouette's width averaged over the view directions
// around the axis equals the curve's width (pbrt-v4's ribbon faces the ray).
TEST(CurveTessellation, TubeCoversTheCurvesWidth) {
  CurveSegments c = curve_segments({{0, 0, 0}, {1, 0, 0}, {2, 0, 0}, {3, 0, 0}}, "bezier", 3, CurveType::Cylinder, {});
  c.width0 = c.width1 = 0.2f;
  const MeshDesc m = tessellate_curve(c);
  ASSERT_FALSE(m.indices.empty());
  EXPECT_TRUE(m.invisible_from_inside);
  const Float r = std::hypot(m.p[0].y, m.p[0].z);
  for (const Vec3& p : m.p) EXPECT_NEAR(std::hypot(p.y, p.z), r, 1e-6f);
  for (size_t t = 0; t < m.indices.size() / 3; ++t) {
    const Vec3 centroid = (m.p[m.indices[3 * t]] + m.p[m.indices[3 * t + 1]] + m.p[m.indices[3 * t + 2]]) / 3.f;
    ASSERT_GT(glm::dot(test::geometric_normal(m, t), Vec3(0.f, centroid.y, centroid.z)), 0.f) << "triangle " << t;
  }
  double mean_width = 0.0;
  const int views = 3600;
  for (int k = 0; k < views; ++k) {
    const double a = 2.0 * M_PI * (k + 0.5) / views;
    const Vec3 across(0.f, static_cast<Float>(std::cos(a)), static_cast<Float>(std::sin(a)));
    Float lo = 1e30f, hi = -1e30f;
    for (const Vec3& p : m.p) lo = std::min(lo, glm::dot(p, across)), hi = std::max(hi, glm::dot(p, across));
    mean_width += (hi - lo) / views;
  }
  EXPECT_NEAR(mean_width, 0.2, 2e-4);
}

// Rings follow the curve: each ring's centre is the Bezier point at its u,
// its radius the width there (width0 .. width1 over the whole curve).
TEST(CurveTessellation, RingsFollowTheCurveAndItsWidth) {
  CurveSegments c = curve_segments({{0, 0, 0}, {1, 2, 0}, {2, -2, 0}, {3, 0, 0}, {4, 1, 1}, {5, 0, 2}, {6, 0, 0}},
                                   "bezier", 3, CurveType::Cylinder, {});
  c.width0 = 0.4f;
  c.width1 = 0.1f;
  const MeshDesc m = tessellate_curve(c);
  const size_t ring = kCurveTubeSides + 1;
  const Float scale = static_cast<Float>(M_PI / (kCurveTubeSides * std::sin(M_PI / kCurveTubeSides)));
  ASSERT_EQ(m.p.size() % ring, 0u);
  int rings_seen = 0, segment = 0;
  Float last_u = -1.f;
  for (size_t first = 0; first < m.p.size(); first += ring) {
    const Float u = m.uv[first].x;
    if (u <= last_u) ++segment;  // u restarts at each segment
    last_u = u;
    Vec3 centre(0.f);
    for (size_t j = 0; j < kCurveTubeSides; ++j) centre += m.p[first + j] / Float(kCurveTubeSides);
    EXPECT_VEC3_NEAR(centre, cubic(c.cps, segment, u), 1e-4f);
    const Float width = glm::mix(c.width0, c.width1, (segment + u) / 2.f);
    EXPECT_NEAR(glm::length(m.p[first] - centre), 0.5f * width * scale, 1e-4f);
    ++rings_seen;
  }
  EXPECT_EQ(segment, 1);
  EXPECT_GT(rings_seen, 4);  // the curved segments are cut into pieces
}

TEST(CurveTessellation, RibbonFollowsItsNormals) {
  CurveSegments c = curve_segments({{0, 0, 0}, {1, 0, 0}, {2, 0, 0}, {3, 0, 0}}, "bezier", 3, CurveType::Ribbon,
                                   {{0, 0, 1}, {0, 1, 0}});
  c.width0 = c.width1 = 0.5f;
  const MeshDesc m = tessellate_curve(c);
  EXPECT_FALSE(m.invisible_from_inside);
  ASSERT_GE(m.p.size(), 4u);
  // At u = 0 the ribbon lies across cross(n0, t) = y, at u = 1 across cross(n1, t) = -z.
  EXPECT_VEC3_NEAR(m.p[1] - m.p[0], Vec3(0, 0.5f, 0), 1e-5f);
  EXPECT_VEC3_NEAR(m.p[m.p.size() - 1] - m.p[m.p.size() - 2], Vec3(0, 0, -0.5f), 1e-5f);
  for (size_t t = 0; t < m.indices.size() / 3; ++t)
    EXPECT_GT(glm::dot(test::geometric_normal(m, t), m.n[m.indices[3 * t]]), 0.f) << "triangle " << t;
}

TEST(CurveTessellation, ParsedWithTransformAndStaysOutward) {
  // A mirroring transform reverses the winding; the tube's faces stay outward.
  SceneDesc s = load_world(
      "Scale -1 1 1\nShape \"curve\" \"point3 P\" [ 0 0 0 1 0.5 0 2 -0.5 0 3 0 0 ] \"string type\" \"cylinder\" "
      "\"float width\" 0.1\nReverseOrientation\nShape \"curve\" \"point3 P\" [ 0 0 0 1 0 0 2 0 0 ] \"integer degree\" 2 "
      "\"string basis\" \"bspline\" \"string type\" \"cylinder\" \"float width\" 0.1\n");
  ASSERT_EQ(s.meshes.size(), 2u);
  for (const MeshDesc& m : s.meshes) {
    ASSERT_FALSE(m.indices.empty());
    for (size_t t = 0; t < m.indices.size() / 3; ++t)
      ASSERT_GT(glm::dot(test::geometric_normal(m, t), m.n[m.indices[3 * t]]), 0.f) << m.where << " triangle " << t;
  }
  EXPECT_LT(s.meshes[0].p[0].x, 0.1f);  // mirrored: x <= 0
}

TEST(CurveTessellation, ErrorsNameTheFileAndLine) {
  const std::string head = "WorldBegin\n";
  EXPECT_NE(test::load_error(head + "Shape \"curve\" \"point3 P\" [ 0 0 0 1 0 0 2 0 0 3 0 0 4 0 0 ]\n")
                .find("bad.pbrt:2: curve has 5 control points"),
            std::string::npos);
  EXPECT_NE(test::load_error(head + "Shape \"curve\" \"point3 P\" [ 0 0 0 1 0 0 ] \"integer degree\" 4\n")
                .find("bad.pbrt:2: curve \"degree\" 4"),
            std::string::npos);
  EXPECT_NE(test::load_error(head + "Shape \"curve\" \"point3 P\" [ 0 0 0 1 0 0 2 0 0 3 0 0 ] \"string basis\" \"nurbs\"\n")
                .find("\"nurbs\" is unknown"),
            std::string::npos);
  EXPECT_NE(test::load_error(head + "Shape \"curve\" \"point3 P\" [ 0 0 0 1 0 0 2 0 0 3 0 0 ] \"string type\" \"tube\"\n")
                .find("\"tube\" is unknown"),
            std::string::npos);
  EXPECT_NE(test::load_error(head + "Shape \"curve\" \"point3 P\" [ 0 0 0 1 0 0 2 0 0 3 0 0 ] \"string type\" \"ribbon\"\n")
                .find("needs 2 normals"),
            std::string::npos);
  EXPECT_NE(test::load_error(head + "Shape \"curve\" \"point3 P\" [ 0 0 0 1 0 0 2 0 0 3 0 0 ] \"float width\" -1\n")
                .find("widths must be finite"),
            std::string::npos);
  EXPECT_NE(test::load_error(head + "Shape \"curve\"\n").find("curve needs \"point3 P\""), std::string::npos);
}

TEST(CurveTessellation, TaperedCurvesCloseToAPoint) {
  SceneDesc s = load_world("Shape \"curve\" \"point3 P\" [ 0 0 0  1 0 0  2 0 0  3 0 0 ] \"string type\" \"cylinder\" "
                           "\"float width0\" 0.1 \"float width1\" 0\n");
  ASSERT_EQ(s.meshes.size(), 1u);
  EXPECT_FALSE(s.meshes[0].indices.empty());
  EXPECT_NEAR(glm::length(s.meshes[0].p.back() - Vec3(3, 0, 0)), 0.f, 1e-6f);  // the tip
}

TEST(CurveTessellation, HostileInputIsAnError) {
  const std::string head = "WorldBegin\n";
  EXPECT_NE(test::load_error(head + "Shape \"curve\" \"point3 P\" [ 0 0 0  1 nan 0  2 0 0  3 0 0 ]\n").find("bad.pbrt:2:"),
            std::string::npos);
  // Finite points whose transform overflows.
  EXPECT_NE(test::load_error(head + "Scale 1e30 1e30 1e30\nShape \"curve\" \"point3 P\" [ 0 0 0  1e10 0 0  2e10 0 0  3e10 0 0 ]\n")
                .find("bad.pbrt:3:"),
            std::string::npos);
  EXPECT_NE(test::load_error(head + "Shape \"curve\" \"point3 P\" [ 0 0 0  1 0 0  2 0 0  3 0 0 ] \"string type\" \"ribbon\" "
                                    "\"normal N\" [ 0 0 0  0 1 0 ]\n")
                .find("finite and not zero"),
            std::string::npos);
  EXPECT_NE(test::load_error(head + "Shape \"curve\" \"point3 P\" [ 0 0 0  1 0 0  2 0 0  3 0 0 ] \"string type\" \"ribbon\" "
                                    "\"normal N\" [ 0 1 0  0 -1 0 ]\n")
                .find("are opposite"),
            std::string::npos);
  // A huge point count with the deepest split is refused before it is tessellated.
  std::string many = "Shape \"curve\" \"integer splitdepth\" 8 \"point3 P\" [ ";
  for (int i = 0; i < 3 * 12000 + 1; ++i) many += std::to_string(i) + " 0 0 ";
  EXPECT_NE(test::load_error(head + many + "]\n").find("triangles (at most"), std::string::npos);
}

TEST(CurveTessellation, DegenerateSegmentsMakeNoTriangles) {
  CurveSegments c = curve_segments({{1, 1, 1}, {1, 1, 1}, {1, 1, 1}, {1, 1, 1}, {2, 1, 1}, {3, 1, 1}, {4, 1, 1}},
                                   "bezier", 3, CurveType::Cylinder, {});
  c.width0 = c.width1 = 0.1f;
  const MeshDesc point_then_line = tessellate_curve(c);
  EXPECT_EQ(point_then_line.indices.size(), 6u * kCurveTubeSides);  // the line's one piece only
  for (uint32_t i : point_then_line.indices) ASSERT_LT(i, point_then_line.p.size());
  c.width0 = c.width1 = 0.f;
  EXPECT_TRUE(tessellate_curve(c).indices.empty());
}

}  // namespace
}  // namespace tessera
