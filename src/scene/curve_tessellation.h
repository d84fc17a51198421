// pbrt-v4's "curve" shape as triangles.
//
// Why triangles: every ray query Tessera has (Embree today, the portable BVH
// and the CUDA backend next) intersects triangles only, and one primitive
// type keeps lights, alpha, media and the guide unchanged. pbrt-v4 intersects
// the cubic Bezier exactly, as a ribbon of the curve's width facing the ray
// ("flat", "cylinder") or oriented by normals ("ribbon"). Here:
//  * flat and cylinder curves become round tubes of `kCurveTubeSides` faces
//    whose mean projected width is the curve's width (the same coverage as
//    pbrt-v4's ribbon facing the ray), with radial vertex normals. The tube is
//    invisible from inside (kTriInvisibleFromInside): a hair BSDF models the
//    whole fibre at one hit, so a ray it sends through the fibre must leave
//    without meeting the far wall; pbrt-v4's curves have no end caps either.
//  * ribbon curves become a two-sided strip across cross(n(u), dp/du), n
//    interpolated between the segment's end normals on the great circle.
// Each segment is cut into pieces along u by how much it turns, at most
// 2^splitdepth (pbrt-v4's refinement depth, default 3).
#pragma once

#include <string>
#include <vector>

#include "scene/scene_desc.h"

namespace tessera {

enum class CurveType { Flat, Cylinder, Ribbon };

constexpr int kCurveTubeSides = 6;
// The most triangles one Shape "curve" may make (its worst case is checked
// before any is made): 2^25, as a displaced plymesh.
constexpr uint64_t kMaxCurveTriangles = uint64_t(1) << 25;

// A curve as pbrt-v4 reads it: cubic Bezier segments in object space.
struct CurveSegments {
  std::vector<Vec3> cps;      // 4 control points per segment
  std::vector<Vec3> normals;  // ribbon: one per segment end (segments + 1), else empty
  Float width0 = 1.f, width1 = 1.f;  // along the whole curve (segment i spans i/n .. (i+1)/n)
  CurveType type = CurveType::Flat;
  int split_depth = 3;
};

// pbrt-v4's "P", "basis" (bezier, bspline), "degree" (2, 3) and "N" as cubic
// Bezier segments. Throws SceneError (without a location) for counts pbrt-v4
// refuses: a Bezier of degree d needs 1 + n d points (n >= 1), a B-spline
// at least d + 1, ribbons one normal per segment end (finite, not zero, no
// two in a row opposite); control points must be finite.
CurveSegments curve_segments(const std::vector<Vec3>& p, const std::string& basis, int degree, CurveType type,
                             const std::vector<Vec3>& normals);

// The triangles of a curve, in object space: uv = (u within its segment,
// around the tube or across the ribbon). A segment that is a point or has no
// width at either end makes no triangles; a tapered one closes to a point.
// Throws SceneError when the worst case exceeds kMaxCurveTriangles.
MeshDesc tessellate_curve(const CurveSegments& curve);

}  // namespace tessera
