#include "scene/curve_tessellation.h"

#include <algorithm>
#include <cmath>

namespace tessera {
namespace {

constexpr double kPiD = 3.14159265358979323846;

Vec3 bezier_point(const Vec3* b, Float u) {
  const Float v = 1.f - u;
  return v * v * v * b[0] + 3.f * v * v * u * b[1] + 3.f * v * u * u * b[2] + u * u * u * b[3];
}

Vec3 bezier_tangent(const Vec3* b, Float u) {
  const Float v = 1.f - u;
  return 3.f * (v * v * (b[1] - b[0]) + 2.f * v * u * (b[2] - b[1]) + u * u * (b[3] - b[2]));
}

Float angle_between(const Vec3& a, const Vec3& b) {
  const Float la = glm::length(a), lb = glm::length(b);
  if (!(la > 0.f) || !(lb > 0.f)) return 0.f;
  return std::acos(std::clamp(glm::dot(a, b) / (la * lb), -1.f, 1.f));
}

// Any unit vector perpendicular to unit t.
Vec3 perpendicular(const Vec3& t) {
  const Vec3 axis = std::fabs(t.x) < 0.9f ? Vec3(1.f, 0.f, 0.f) : Vec3(0.f, 1.f, 0.f);
  return glm::normalize(glm::cross(t, axis));
}

// The unit tangent at u, or the chord's direction where the derivative
// vanishes (a control point doubled at an end); false for a segment that is a point.
bool unit_tangent(const Vec3* b, Float u, Vec3* t) {
  Vec3 d = bezier_tangent(b, u);
  if (!(glm::dot(d, d) > 1e-30f)) d = b[3] - b[0];
  if (!(glm::dot(d, d) > 1e-30f)) return false;
  *t = glm::normalize(d);
  return true;
}

// Pieces along u: enough that each turns (and a ribbon twists, by
// `twist`) by at most about 8.6 degrees, at most 2^splitdepth.
int pieces_for(const Vec3* b, Float twist, int split_depth) {
  const Float turning =
      angle_between(b[1] - b[0], b[2] - b[1]) + angle_between(b[2] - b[1], b[3] - b[2]) + twist;
  const int most = 1 << std::clamp(split_depth, 0, 8);
  if (!(turning >= 0.f)) return most;  // NaN from overflowing points: never cast it
  return static_cast<int>(std::clamp(std::ceil(turning / 0.15f), 1.f, static_cast<Float>(most)));
}

// Unit n(u) on the great circle from n0 to n1 (pbrt-v4's ribbon normal).
Vec3 ribbon_normal(const Vec3& n0, const Vec3& n1, Float u) {
  const Float theta = angle_between(n0, n1);
  if (theta < 1e-4f) return glm::normalize(glm::mix(n0, n1, u));
  const Float s = std::sin(theta);
  return glm::normalize((std::sin((1.f - u) * theta) / s) * n0 + (std::sin(u * theta) / s) * n1);
}

}  // namespace

CurveSegments curve_segments(const std::vector<Vec3>& p, const std::string& basis, int degree, CurveType type,
                             const std::vector<Vec3>& normals) {
  for (const Vec3& q : p)
    if (!is_finite(q)) throw SceneError("curve control points must be finite (NaN or Inf in \"P\")");
  if (degree != 2 && degree != 3)
    throw SceneError("curve \"degree\" " + std::to_string(degree) + " is not supported (2 or 3)");
  const size_t d = static_cast<size_t>(degree);
  size_t segments = 0;
  if (basis == "bezier") {
    if (p.size() < d + 1 || (p.size() - 1) % d != 0)
      throw SceneError("curve has " + std::to_string(p.size()) + " control points: a degree-" + std::to_string(d) +
                       " Bezier needs 1 + " + std::to_string(d) + " n (n >= 1)");
    segments = (p.size() - 1) / d;
  } else if (basis == "bspline") {
    if (p.size() < d + 1)
      throw SceneError("curve has " + std::to_string(p.size()) + " control points: a degree-" + std::to_string(d) +
                       " B-spline needs at least " + std::to_string(d + 1));
    segments = p.size() - d;
  } else {
    throw SceneError("curve \"basis\" \"" + basis + "\" is unknown (bezier, bspline)");
  }
  CurveSegments c;
  c.type = type;
  if (type == CurveType::Ribbon) {
    if (normals.size() != segments + 1)
      throw SceneError("ribbon curve needs " + std::to_string(segments + 1) + " normals \"N\" (one per segment end), has " +
                       std::to_string(normals.size()));
    for (const Vec3& n : normals)
      if (!(glm::length(n) > 0.f) || !(glm::length(n) < kInfinity))
        throw SceneError("ribbon curve normals \"N\" must be finite and not zero");
    c.normals.reserve(normals.size());
    for (size_t i = 0; i < normals.size(); ++i) {
      c.normals.push_back(glm::normalize(normals[i]));
      if (i > 0 && glm::dot(c.normals[i], c.normals[i - 1]) < -0.9999f)
        throw SceneError("ribbon curve normals \"N\" " + std::to_string(i - 1) + " and " + std::to_string(i) +
                         " are opposite: the ribbon's twist between them is undefined");
    }
  }
  c.cps.reserve(4 * segments);
  for (size_t s = 0; s < segments; ++s) {
    const Vec3* q = p.data() + (basis == "bezier" ? s * d : s);
    Vec3 b[4];
    if (basis == "bezier" && d == 3) {
      b[0] = q[0], b[1] = q[1], b[2] = q[2], b[3] = q[3];
    } else if (basis == "bezier") {  // quadratic -> cubic: the same curve
      b[0] = q[0], b[1] = glm::mix(q[0], q[1], 2.f / 3.f), b[2] = glm::mix(q[1], q[2], 1.f / 3.f), b[3] = q[2];
    } else if (d == 3) {  // uniform cubic B-spline span -> Bezier
      b[0] = (q[0] + 4.f * q[1] + q[2]) / 6.f;
      b[1] = (2.f * q[1] + q[2]) / 3.f;
      b[2] = (q[1] + 2.f * q[2]) / 3.f;
      b[3] = (q[1] + 4.f * q[2] + q[3]) / 6.f;
    } else {  // uniform quadratic B-spline span -> quadratic Bezier -> cubic
      const Vec3 a0 = 0.5f * (q[0] + q[1]), a2 = 0.5f * (q[1] + q[2]);
      b[0] = a0, b[1] = glm::mix(a0, q[1], 2.f / 3.f), b[2] = glm::mix(q[1], a2, 1.f / 3.f), b[3] = a2;
    }
    c.cps.insert(c.cps.end(), b, b + 4);
  }
  return c;
}

MeshDesc tessellate_curve(const CurveSegments& curve) {
  MeshDesc m;
  const size_t segments = curve.cps.size() / 4;
  const bool ribbon = curve.type == CurveType::Ribbon;
  // Refused before anything is allocated: at most 2^splitdepth pieces per segment.
  const uint64_t most_pieces = uint64_t(1) << std::clamp(curve.split_depth, 0, 8);
  const uint64_t most_triangles = segments * most_pieces * (ribbon ? 2 : 2 * kCurveTubeSides);
  if (most_triangles > kMaxCurveTriangles)
    throw SceneError("curve would make up to " + std::to_string(most_triangles) + " triangles (at most " +
                     std::to_string(kMaxCurveTriangles) + " per shape; lower \"splitdepth\")");
  // A regular n-gon of circumradius r has mean projected width 2 n r sin(pi/n) / pi.
  const Float tube_scale = static_cast<Float>(kPiD / (kCurveTubeSides * std::sin(kPiD / kCurveTubeSides)));
  Vec3 reference(0.f);  // the tube's first side, carried along the curve so that rings do not twist
  for (size_t s = 0; s < segments; ++s) {
    const Vec3* b = curve.cps.data() + 4 * s;
    const Float twist = ribbon ? angle_between(curve.normals[s], curve.normals[s + 1]) : 0.f;
    const int pieces = pieces_for(b, twist, curve.split_depth);
    const Float w0 = glm::mix(curve.width0, curve.width1, static_cast<Float>(s) / segments);
    const Float w1 = glm::mix(curve.width0, curve.width1, static_cast<Float>(s + 1) / segments);
    const uint32_t first = static_cast<uint32_t>(m.p.size());
    const int ring_size = ribbon ? 2 : kCurveTubeSides + 1;
    // A segment without width (both ends 0) or direction makes nothing; a
    // tapered one closes to a point (those triangles are dropped as degenerate).
    bool ok = w0 > 0.f || w1 > 0.f;
    for (int i = 0; i <= pieces && ok; ++i) {
      const Float u = static_cast<Float>(i) / pieces;
      const Vec3 c = bezier_point(b, u);
      const Float width = glm::max(glm::mix(w0, w1, u), 0.f);
      Vec3 t;
      if (!unit_tangent(b, u, &t) || !is_finite(c)) {
        ok = false;
        break;
      }
      if (ribbon) {
        const Vec3 n = ribbon_normal(curve.normals[s], curve.normals[s + 1], u);
        Vec3 across = glm::cross(n, t);
        if (!(glm::dot(across, across) > 1e-20f)) across = perpendicular(t);
        across = glm::normalize(across);
        for (int j = 0; j < 2; ++j) {
          m.p.push_back(c + (j == 0 ? -0.5f : 0.5f) * width * across);
          m.n.push_back(n);
          m.uv.emplace_back(u, static_cast<Float>(j));
        }
        continue;
      }
      // Parallel transport: the last ring's first side, made perpendicular to t.
      Vec3 e1 = reference - t * glm::dot(reference, t);
      e1 = glm::dot(e1, e1) > 1e-12f ? glm::normalize(e1) : perpendicular(t);
      reference = e1;
      const Vec3 e2 = glm::cross(t, e1);
      const Float r = 0.5f * width * tube_scale;
      for (int j = 0; j <= kCurveTubeSides; ++j) {
        const double phi = 2.0 * kPiD * (j % kCurveTubeSides) / kCurveTubeSides;
        const Vec3 dir = static_cast<Float>(std::cos(phi)) * e1 + static_cast<Float>(std::sin(phi)) * e2;
        m.p.push_back(c + r * dir);
        m.n.push_back(dir);
        m.uv.emplace_back(u, static_cast<Float>(j) / kCurveTubeSides);
      }
    }
    if (!ok) {  // a piece without width or direction: drop the segment's vertices
      m.p.resize(first);
      m.n.resize(first);
      m.uv.resize(first);
      continue;
    }
    // Quad (a, b, c, d) = (ring i side j, ring i side j+1, ring i+1 side j+1,
    // ring i+1 side j): (a, b, c), (a, c, d) make cross(p0 - p2, p1 - p2)
    // point outwards for the tube (along cross(dp/dphi, dp/du)); the ribbon's
    // reversed pair points along its normal.
    for (int i = 0; i < pieces; ++i)
      for (int j = 0; j + 1 < ring_size; ++j) {
        const uint32_t a = first + i * ring_size + j, bb = a + 1, cc = a + ring_size + 1, d = a + ring_size;
        if (ribbon)
          m.indices.insert(m.indices.end(), {a, cc, bb, a, d, cc});
        else
          m.indices.insert(m.indices.end(), {a, bb, cc, a, cc, d});
      }
  }
  m.invisible_from_inside = !ribbon;
  return m;
}

}  // namespace tessera
