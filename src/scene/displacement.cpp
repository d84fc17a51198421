#include "scene/displacement.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <unordered_map>

#include "kernels/texture_eval.h"

namespace tessera {
namespace {

[[noreturn]] void fail(const std::string& reason) { throw SceneError("displacement: " + reason); }

}  // namespace

std::vector<Vec3> vertex_normals(const std::vector<Vec3>& p, const std::vector<uint32_t>& indices) {
  std::vector<Vec3> n(p.size(), Vec3(0.f));
  for (size_t t = 0; t + 2 < indices.size(); t += 3) {
    const uint32_t a = indices[t], b = indices[t + 1], c = indices[t + 2];
    Vec3 fn = glm::cross(p[b] - p[a], p[c] - p[b]);
    const Float len = glm::length(fn);
    if (!(len > 0.f)) continue;
    fn /= len;
    n[a] += fn;
    n[b] += fn;
    n[c] += fn;
  }
  for (Vec3& v : n) {
    const Float len = glm::length(v);
    if (len > 0.f) v /= len;
  }
  return n;
}

void displace_mesh(MeshDesc& m, const Mat4& world_from_object, Float edge_length, const DisplacementFn& displacement) {
  if (m.uv.empty()) fail("the mesh has no uv coordinates (pbrt-v4 requires them to displace)");
  if (!(edge_length > 0.f)) fail("\"edgelength\" must be positive");
  if (m.n.empty()) m.n = vertex_normals(m.p, m.indices);
  auto world_length = [&](uint32_t a, uint32_t b) {
    return glm::length(Vec3(world_from_object * Vec4(m.p[a], 1.f)) - Vec3(world_from_object * Vec4(m.p[b], 1.f)));
  };
  // Refinement roughly quarters a triangle per halving of its longest edge:
  // refuse at once what would far exceed the cap, instead of working up to it.
  double estimate = 0;
  for (size_t t = 0; t + 2 < m.indices.size(); t += 3) {
    const uint32_t a = m.indices[t], b = m.indices[t + 1], c = m.indices[t + 2];
    const double longest = std::max({world_length(a, b), world_length(b, c), world_length(c, a)});
    estimate += std::max(1.0, 0.5 * (longest / edge_length) * (longest / edge_length));
  }
  if (!(estimate <= 4.0 * kMaxDisplacedTriangles))
    fail("refining to \"edgelength\" " + std::to_string(edge_length) + " would make more than " +
         std::to_string(kMaxDisplacedTriangles) + " triangles");
  // Longest-edge bisection (pbrt-v4's Refine), with an explicit stack and a
  // shared midpoint per split edge so that neighbours stay connected.
  std::unordered_map<uint64_t, uint32_t> midpoint;
  std::vector<uint32_t> out;
  std::vector<std::array<uint32_t, 3>> stack;
  for (size_t t = 0; t + 2 < m.indices.size(); t += 3) {
    stack.push_back({m.indices[t], m.indices[t + 1], m.indices[t + 2]});
    while (!stack.empty()) {
      const std::array<uint32_t, 3> tri = stack.back();
      stack.pop_back();
      const Float d01 = world_length(tri[0], tri[1]), d12 = world_length(tri[1], tri[2]), d20 = world_length(tri[2], tri[0]);
      if (d01 < edge_length && d12 < edge_length && d20 < edge_length) {
        out.insert(out.end(), tri.begin(), tri.end());
        if (out.size() / 3 > kMaxDisplacedTriangles)
          fail("refining to \"edgelength\" " + std::to_string(edge_length) + " would make more than " +
               std::to_string(kMaxDisplacedTriangles) + " triangles");
        continue;
      }
      // The first two vertices span the longest edge.
      std::array<uint32_t, 3> v;
      if (d01 > d12) v = d01 > d20 ? std::array<uint32_t, 3>{tri[0], tri[1], tri[2]} : std::array<uint32_t, 3>{tri[2], tri[0], tri[1]};
      else v = d12 > d20 ? std::array<uint32_t, 3>{tri[1], tri[2], tri[0]} : std::array<uint32_t, 3>{tri[2], tri[0], tri[1]};
      const uint64_t key = (uint64_t(std::min(v[0], v[1])) << 32) | std::max(v[0], v[1]);
      auto [it, inserted] = midpoint.try_emplace(key, static_cast<uint32_t>(m.p.size()));
      if (inserted) {
        if (m.p.size() >= 2 * kMaxDisplacedTriangles) fail("too many vertices");
        m.p.push_back(0.5f * (m.p[v[0]] + m.p[v[1]]));
        const Vec3 n = m.n[v[0]] + m.n[v[1]];
        m.n.push_back(glm::length(n) > 0.f ? glm::normalize(n) : n);
        m.uv.push_back(0.5f * (m.uv[v[0]] + m.uv[v[1]]));
      }
      const uint32_t mid = it->second;
      if (!std::isfinite(world_length(v[0], mid))) fail("non-finite vertex positions");
      // Float precision can stop a split from shortening the edge (huge
      // coordinates, tiny edgelength): keep the triangle as it is.
      if (m.p[mid] == m.p[v[0]] || m.p[mid] == m.p[v[1]]) {
        out.insert(out.end(), tri.begin(), tri.end());
        continue;
      }
      stack.push_back({mid, v[1], v[2]});
      stack.push_back({v[0], mid, v[2]});
    }
  }
  m.indices = std::move(out);
  for (size_t i = 0; i < m.p.size(); ++i) {
    const Float d = displacement(m.p[i], m.uv[i]);
    if (!std::isfinite(d)) fail("the texture's value is not finite");
    m.p[i] += d * m.n[i];
  }
  m.n = vertex_normals(m.p, m.indices);
}

HostTextures::HostTextures(const SceneDesc& scene) {
  for (const ImageDesc& img : scene.images) images_.push_back(ImageView{img.width, img.height, img.texels.data()});
  view_.textures = scene.textures.data();
  view_.images = images_.data();
}

Float HostTextures::eval(const TextureSlot& slot, const Vec3& p, const Vec3& n, Vec2 uv) const {
  return eval_slot(view_, slot, TexturePoint{p, n, uv}).x;
}

}  // namespace tessera
