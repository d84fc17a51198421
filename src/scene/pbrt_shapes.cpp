#include "scene/pbrt_shapes.h"

#include <algorithm>
#include <cmath>
#include <filesystem>

#include "scene/curve_tessellation.h"
#include "scene/pbrt_paths.h"
#include "scene/loop_subdivision.h"
#include "scene/ply_mesh.h"

namespace tessera {
namespace {

[[noreturn]] void fail(const ShapeContext& ctx, const std::string& problem) {
  throw SceneError(ctx.where + ": " + problem);
}

void warn(const ShapeContext& ctx, const std::string& message) {
  if (ctx.warnings) ctx.warnings->push_back(ctx.where + ": " + message);
}

// Indices must be triangles (or patches of `per_face`) within the vertex list.
std::vector<uint32_t> checked_indices(const std::vector<int32_t>& raw, size_t vertex_count, size_t per_face,
                                      const std::string& shape, const ShapeContext& ctx) {
  if (raw.size() % per_face != 0)
    fail(ctx, shape + " \"indices\" count " + std::to_string(raw.size()) + " is not a multiple of " +
                  std::to_string(per_face));
  std::vector<uint32_t> out;
  out.reserve(raw.size());
  for (int32_t i : raw) {
    if (i < 0 || static_cast<size_t>(i) >= vertex_count)
      fail(ctx, shape + " index " + std::to_string(i) + " out of range (" + std::to_string(vertex_count) +
                    " vertices)");
    out.push_back(static_cast<uint32_t>(i));
  }
  return out;
}

// Optional per-vertex data must match the vertex count; pbrt-v4 drops it otherwise.
template <typename T>
void drop_if_mismatched(std::vector<T>& data, size_t vertex_count, const char* name, const ShapeContext& ctx) {
  if (!data.empty() && data.size() != vertex_count) {
    warn(ctx, std::string("\"") + name + "\" has " + std::to_string(data.size()) + " entries for " +
                  std::to_string(vertex_count) + " vertices; ignored");
    data.clear();
  }
}

MeshDesc triangle_mesh(const ParamSet& params, const ShapeContext& ctx) {
  MeshDesc m;
  m.p = params.get_point3s("P");
  params.release("P");
  if (m.p.empty()) fail(ctx, "trianglemesh needs \"point3 P\"");
  static const std::vector<int32_t> kOneTriangle = {0, 1, 2};
  const std::vector<int32_t>& given = params.get_ints("indices");
  if (given.empty() && m.p.size() != 3) fail(ctx, "trianglemesh needs \"integer indices\" unless it has exactly 3 vertices");
  m.indices = checked_indices(given.empty() ? kOneTriangle : given, m.p.size(), 3, "trianglemesh", ctx);
  params.release("indices");
  m.uv = params.get_point2s("uv");
  if (m.uv.empty()) m.uv = params.get_point2s("st");  // pbrt-v3 name
  m.n = params.get_normals("N");
  drop_if_mismatched(m.uv, m.p.size(), "uv", ctx);
  drop_if_mismatched(m.n, m.p.size(), "N", ctx);
  if (params.find_any("S")) warn(ctx, "per-vertex tangents \"S\" are not supported; ignored");
  return m;
}

MeshDesc bilinear_mesh(const ParamSet& params, const ShapeContext& ctx) {
  std::vector<Vec3> p = params.get_point3s("P");
  if (p.empty()) fail(ctx, "bilinearmesh needs \"point3 P\"");
  static const std::vector<int32_t> kOneQuad = {0, 1, 2, 3};
  const std::vector<int32_t>& given = params.get_ints("indices");
  if (given.empty() && p.size() != 4) fail(ctx, "bilinearmesh needs \"integer indices\" unless it has exactly 4 vertices");
  std::vector<uint32_t> quads = checked_indices(given.empty() ? kOneQuad : given, p.size(), 4, "bilinearmesh", ctx);
  MeshDesc m;
  m.p = std::move(p);
  m.uv = params.get_point2s("uv");
  m.n = params.get_normals("N");
  drop_if_mismatched(m.uv, m.p.size(), "uv", ctx);
  drop_if_mismatched(m.n, m.p.size(), "N", ctx);
  // Patch (p00, p10, p01, p11): both halves keep pbrt's dpdu x dpdv orientation.
  for (size_t q = 0; q < quads.size(); q += 4) {
    uint32_t p00 = quads[q], p10 = quads[q + 1], p01 = quads[q + 2], p11 = quads[q + 3];
    m.indices.insert(m.indices.end(), {p00, p10, p11, p00, p11, p01});
  }
  m.triangles_per_shape = 2;
  return m;
}

MeshDesc ply_mesh(const ParamSet& params, const ShapeContext& ctx) {
  std::string name = params.get_string("filename", "");
  if (name.empty()) fail(ctx, "plymesh needs \"string filename\"");
  std::string path = resolve_scene_path(name, ctx.including_dir, ctx.search_dir);
  if (ctx.files_read) ctx.files_read->push_back(path);
  std::error_code ec;
  if (!std::filesystem::exists(path, ec)) fail(ctx, "plymesh file '" + path + "' not found");
  PlyMesh ply;
  try {
    ply = load_ply_mesh(path);
  } catch (const SceneError& e) {
    fail(ctx, e.what());
  }
  if (ply.skipped_faces > 0)
    warn(ctx, "plymesh '" + name + "': " + std::to_string(ply.skipped_faces) +
                  " faces that are neither triangles nor quads ignored (as pbrt-v4 does)");
  MeshDesc m;
  // A PLY of quads alone is pbrt-v4's bilinear patches: two triangles each.
  if (ply.quads > 0 && ply.quads * 6 == ply.indices.size()) m.triangles_per_shape = 2;
  m.mixed_faces = ply.quads > 0 && ply.quads * 6 != ply.indices.size();
  m.p = std::move(ply.p);
  m.n = std::move(ply.n);
  m.uv = std::move(ply.uv);
  m.indices = std::move(ply.indices);
  const Float edge_length = params.get_float("edgelength", 1.f);
  if (std::optional<std::string> tex = params.get_texture("displacement")) {
    if (!ctx.float_texture) fail(ctx, "plymesh displacement is not available here");
    try {
      displace_mesh(m, ctx.world_from_object, edge_length, ctx.float_texture(*tex));
    } catch (const SceneError& e) {
      fail(ctx, "plymesh '" + name + "': " + e.what());
    }
  }
  return m;
}

// pbrt-v4's "loopsubdiv": indices and P as trianglemesh, "levels" (default 3).
MeshDesc loop_subdiv_mesh(const ParamSet& params, const ShapeContext& ctx) {
  std::vector<Vec3> p = params.get_point3s("P");
  if (p.empty()) fail(ctx, "loopsubdiv needs \"point3 P\"");
  const std::vector<int32_t>& raw = params.get_ints("indices");
  if (raw.empty()) fail(ctx, "loopsubdiv needs \"integer indices\"");
  const int levels = params.get_int("levels", 3);
  if (levels < 0) fail(ctx, "loopsubdiv \"levels\" must not be negative");
  SubdividedMesh sub;
  try {
    sub = loop_subdivide(p, checked_indices(raw, p.size(), 3, "loopsubdiv", ctx), levels);
  } catch (const SceneError& e) {
    fail(ctx, e.what());
  }
  MeshDesc m;
  m.p = std::move(sub.p);
  m.n = std::move(sub.n);
  m.indices = std::move(sub.indices);
  return m;
}

// Grid over (ring, segment) with quads split so that cross(p0 - p2, p1 - p2)
// follows d(ring) x d(segment). Rows whose first or last ring collapses to a
// point (sphere poles, disk centre) lose the degenerate half.
void add_grid_triangles(MeshDesc& m, int rings, int segments, bool first_ring_is_point, bool last_ring_is_point) {
  auto v = [&](int i, int j) { return static_cast<uint32_t>(i * (segments + 1) + j); };
  for (int i = 0; i < rings; ++i)
    for (int j = 0; j < segments; ++j) {
      uint32_t a = v(i, j), b = v(i, j + 1), c = v(i + 1, j + 1), d = v(i + 1, j);
      if (!(i == 0 && first_ring_is_point)) m.indices.insert(m.indices.end(), {d, b, a});
      if (!(i == rings - 1 && last_ring_is_point)) m.indices.insert(m.indices.end(), {b, d, c});
    }
}

constexpr int kSphereThetaSteps = 64, kSpherePhiSteps = 128;

MeshDesc sphere_mesh(const ParamSet& params, const ShapeContext& ctx) {
  const Float r = params.get_float("radius", 1.f);
  if (!(r > 0.f) || !std::isfinite(r)) fail(ctx, "sphere radius must be positive");
  // pbrt-v4's partial spheres: z clamped to [-r, r], phi up to phimax; v runs
  // from zmin (0) to zmax (1), u = phi / phimax.
  const Float z0 = std::clamp(std::min(params.get_float("zmin", -r), params.get_float("zmax", r)), -r, r);
  const Float z1 = std::clamp(std::max(params.get_float("zmin", -r), params.get_float("zmax", r)), -r, r);
  const Float phimax = glm::radians(std::clamp(params.get_float("phimax", 360.f), 0.f, 360.f));
  if (!(z1 > z0) || !(phimax > 0.f)) fail(ctx, "sphere zmin, zmax and phimax leave no surface");
  const Float theta_top = std::acos(z1 / r), theta_bottom = std::acos(z0 / r);
  const bool top_pole = z1 >= r, bottom_pole = z0 <= -r;
  MeshDesc m;
  // Rings run from the top (smallest theta) down, so d(theta) x d(phi) is outward.
  for (int i = 0; i <= kSphereThetaSteps; ++i) {
    const Float theta = theta_top + (theta_bottom - theta_top) * i / kSphereThetaSteps;
    for (int j = 0; j <= kSpherePhiSteps; ++j) {
      const Float phi = phimax * j / kSpherePhiSteps;
      Vec3 dir(std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi), std::cos(theta));
      if ((i == 0 && top_pole) || (i == kSphereThetaSteps && bottom_pole))
        dir = Vec3(0.f, 0.f, i == 0 ? 1.f : -1.f);  // exact poles
      m.p.push_back(r * dir);
      m.n.push_back(dir);
      m.uv.emplace_back(phi / phimax, (theta - theta_bottom) / (theta_top - theta_bottom));
    }
  }
  add_grid_triangles(m, kSphereThetaSteps, kSpherePhiSteps, top_pole, bottom_pole);
  m.triangles_per_shape = 0;
  m.shape_area = phimax * r * (z1 - z0);
  return m;
}

constexpr int kCylinderRings = 8, kCylinderSegments = 128;

// pbrt-v4's cylinder: radius, zmin, zmax, phimax; u = phi / phimax, v along z.
MeshDesc cylinder_mesh(const ParamSet& params, const ShapeContext& ctx) {
  const Float r = params.get_float("radius", 1.f);
  const Float zmin = params.get_float("zmin", -1.f), zmax = params.get_float("zmax", 1.f);
  const Float phimax = glm::radians(std::clamp(params.get_float("phimax", 360.f), 0.f, 360.f));
  if (!(r > 0.f) || !std::isfinite(r)) fail(ctx, "cylinder radius must be positive");
  if (!(zmax != zmin) || !std::isfinite(zmin) || !std::isfinite(zmax)) fail(ctx, "cylinder needs zmin != zmax");
  if (!(phimax > 0.f)) fail(ctx, "cylinder phimax must be positive");
  const Float z0 = std::min(zmin, zmax), z1 = std::max(zmin, zmax);
  MeshDesc m;
  // Rings run from z1 down, so d(ring) x d(phi) points outwards (pbrt-v4's dp/du x dp/dv).
  for (int i = 0; i <= kCylinderRings; ++i) {
    const Float z = z1 - (z1 - z0) * i / kCylinderRings;
    for (int j = 0; j <= kCylinderSegments; ++j) {
      const Float phi = phimax * j / kCylinderSegments;
      const Vec3 dir(std::cos(phi), std::sin(phi), 0.f);
      m.p.emplace_back(r * dir.x, r * dir.y, z);
      m.n.push_back(dir);
      m.uv.emplace_back(phi / phimax, (z - z0) / (z1 - z0));
    }
  }
  add_grid_triangles(m, kCylinderRings, kCylinderSegments, false, false);
  m.triangles_per_shape = 0;
  m.shape_area = (z1 - z0) * r * phimax;
  return m;
}

constexpr int kDiskRings = 4, kDiskSegments = 128;

MeshDesc disk_mesh(const ParamSet& params, const ShapeContext& ctx) {
  const Float h = params.get_float("height", 0.f), radius = params.get_float("radius", 1.f);
  const Float inner = params.get_float("innerradius", 0.f);
  const Float phimax = glm::radians(std::clamp(params.get_float("phimax", 360.f), 0.f, 360.f));
  if (!(radius > inner) || inner < 0.f) fail(ctx, "disk needs 0 <= innerradius < radius");
  if (!(phimax > 0.f)) fail(ctx, "disk phimax must be positive");
  MeshDesc m;
  // Rings run outward, so d(r) x d(phi) is +z.
  for (int i = 0; i <= kDiskRings; ++i) {
    Float rr = inner + (radius - inner) * i / kDiskRings;
    for (int j = 0; j <= kDiskSegments; ++j) {
      Float phi = phimax * j / kDiskSegments;
      m.p.emplace_back(rr * std::cos(phi), rr * std::sin(phi), h);
      m.uv.emplace_back(phi / phimax, (radius - rr) / (radius - inner));
    }
  }
  add_grid_triangles(m, kDiskRings, kDiskSegments, inner == 0.f, false);
  m.triangles_per_shape = 0;
  m.shape_area = phimax * 0.5f * (radius * radius - inner * inner);
  return m;
}

// pbrt-v4's "curve": P, basis, degree, type, N, width/width0/width1,
// splitdepth; tessellated (curve_tessellation.h).
MeshDesc curve_mesh(const ParamSet& params, const ShapeContext& ctx) {
  const std::vector<Vec3> p = params.get_point3s("P");
  if (p.empty()) fail(ctx, "curve needs \"point3 P\"");
  params.release("P");
  const std::string type_name = params.get_string("type", "flat");
  CurveType type = CurveType::Flat;
  if (type_name == "cylinder")
    type = CurveType::Cylinder;
  else if (type_name == "ribbon")
    type = CurveType::Ribbon;
  else if (type_name != "flat")
    fail(ctx, "curve \"type\" \"" + type_name + "\" is unknown (flat, cylinder, ribbon)");
  std::vector<Vec3> normals = params.get_normals("N");
  if (!normals.empty() && type != CurveType::Ribbon) {
    warn(ctx, "curve normals \"N\" are only used by \"ribbon\" curves; ignored");
    normals.clear();
  }
  const Float width = params.get_float("width", 1.f);
  CurveSegments c;
  try {
    c = curve_segments(p, params.get_string("basis", "bezier"), params.get_int("degree", 3), type, normals);
  } catch (const SceneError& e) {
    fail(ctx, e.what());
  }
  c.width0 = params.get_float("width0", width);
  c.width1 = params.get_float("width1", width);
  if (!(c.width0 >= 0.f) || !(c.width1 >= 0.f) || !std::isfinite(c.width0) || !std::isfinite(c.width1))
    fail(ctx, "curve widths must be finite and not negative");
  c.split_depth = params.get_int("splitdepth", 3);
  if (type == CurveType::Flat) {
    // Once per scene: hair files hold thousands of curves.
    const std::string note = "\"flat\" curves are rendered as round tubes";
    bool said = false;
    if (ctx.warnings)
      for (const std::string& w : *ctx.warnings) said = said || w.find(note) != std::string::npos;
    if (!said)
      warn(ctx, note + ": the same silhouette, and for hair the same offsets across the fibre; other materials "
                       "shade as on a cylinder (said once for all curves)");
  }
  try {
    return tessellate_curve(c);
  } catch (const SceneError& e) {
    fail(ctx, e.what());
  }
}

Mat3 normal_matrix(const Mat4& m) { return glm::transpose(glm::inverse(Mat3(m))); }

void check_finite(const MeshDesc& m, const ShapeContext& ctx) {
  for (const Vec3& p : m.p)
    if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z))
      fail(ctx, "non-finite vertex coordinates (NaN or Inf)");
}

}  // namespace

bool swaps_handedness(const Mat4& m) { return glm::determinant(Mat3(m)) < 0.f; }

void transform_mesh(MeshDesc& mesh, const Mat4& m) {
  const Mat3 nm = normal_matrix(m);
  auto points = [&](std::vector<Vec3>& ps) {
    for (Vec3& p : ps) p = Vec3(m * Vec4(p, 1.f));
  };
  auto normals = [&](std::vector<Vec3>& ns) {
    for (Vec3& n : ns) {
      Vec3 t = nm * n;
      Float len = glm::length(t);
      n = len > 0.f ? t / len : n;
    }
  };
  points(mesh.p);
  points(mesh.p_end);
  normals(mesh.n);
  normals(mesh.n_end);
  if (swaps_handedness(m)) mesh.flip_normals = !mesh.flip_normals;
}

void add_motion(MeshDesc& mesh, const Mat4& end_from_start) {
  mesh.p_end = mesh.p;
  mesh.n_end = mesh.n;
  const Mat3 nm = normal_matrix(end_from_start);
  for (Vec3& p : mesh.p_end) {
    p = Vec3(end_from_start * Vec4(p, 1.f));
    if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z))
      throw SceneError(mesh.where + ": non-finite vertex coordinates at the end of the motion (NaN or Inf)");
  }
  for (Vec3& n : mesh.n_end) {
    const Vec3 t = nm * n;
    const Float len = glm::length(t);
    n = len > 0.f ? t / len : n;
  }
}

std::optional<MeshDesc> make_shape_mesh(const std::string& type, const ParamSet& params, const ShapeContext& ctx) {
  MeshDesc m;
  bool quadric = false;
  if (type == "trianglemesh") {
    m = triangle_mesh(params, ctx);
  } else if (type == "bilinearmesh") {
    m = bilinear_mesh(params, ctx);
  } else if (type == "plymesh") {
    m = ply_mesh(params, ctx);
  } else if (type == "loopsubdiv") {
    m = loop_subdiv_mesh(params, ctx);
  } else if (type == "sphere") {
    m = sphere_mesh(params, ctx);
    quadric = true;
  } else if (type == "disk") {
    m = disk_mesh(params, ctx);
    quadric = true;
  } else if (type == "cylinder") {
    m = cylinder_mesh(params, ctx);
    quadric = true;
  } else if (type == "curve") {
    m = curve_mesh(params, ctx);
  } else {
    warn(ctx, "unsupported shape \"" + type + "\"; skipped");
    return std::nullopt;
  }
  m.where = ctx.where;
  transform_mesh(m, ctx.world_from_object);  // flip_normals = swaps handedness
  const bool swaps = m.flip_normals;
  if (m.invisible_from_inside) {
    // A tube's faces stay outward whatever the orientation: its inside is never seen.
    m.flip_normals = swaps;
  } else if (!quadric) {
    // Triangles: pbrt-v4 flips the world-space cross product.
    m.flip_normals = ctx.reverse_orientation != swaps;
  } else {
    // Quadrics: pbrt-v4 flips the *object-space* normal for reverse XOR swaps and
    // then transforms it, so a mirrored sphere faces inward. Reproduce that:
    // the world normal is the transformed outward normal, negated for rev XOR swaps.
    m.flip_normals = ctx.reverse_orientation;
    if (ctx.reverse_orientation != swaps)
      for (Vec3& n : m.n) n = -n;
  }
  check_finite(m, ctx);
  return m;
}

}  // namespace tessera
