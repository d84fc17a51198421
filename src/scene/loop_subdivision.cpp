// Loop subdivision as pbrt-v4 does it (its rules and limit normals), on flat
// index arrays: the topology (face neighbours, each vertex's ordered one-ring)
// is rebuilt from the triangle list at every level, which keeps each step a
// plain pass over arrays and lets every malformed case become an error
// instead of a walk through dangling pointers.
#include "scene/loop_subdivision.h"

#include <array>
#include <cmath>
#include <unordered_map>

#include "scene/scene_desc.h"

namespace tessera {
namespace {

using Face = std::array<uint32_t, 3>;

[[noreturn]] void fail(const std::string& reason) { throw SceneError("loopsubdiv: " + reason); }

struct Edge {
  uint32_t a, b;        // as first seen: a -> b in face f0
  int32_t f0, k0;       // face and its edge number (edge k runs v[k] -> v[k+1])
  int32_t f1 = -1;      // the face on the other side, -1 on the boundary
};

struct Topology {
  std::vector<std::array<int32_t, 3>> neighbour;  // face across edge k, -1 on the boundary
  std::vector<std::array<uint32_t, 3>> edge_of;   // edge id of each face edge
  std::vector<Edge> edges;
  // Each vertex's one-ring, ordered as pbrt-v4 walks it, flattened.
  std::vector<uint32_t> ring_start;  // size vertices + 1
  std::vector<uint32_t> ring;
  std::vector<uint8_t> boundary;

  uint32_t valence(uint32_t v) const { return ring_start[v + 1] - ring_start[v]; }
  const uint32_t* ring_of(uint32_t v) const { return ring.data() + ring_start[v]; }
};

int local_index(const Face& f, uint32_t v) { return f[0] == v ? 0 : f[1] == v ? 1 : 2; }

Topology build_topology(const std::vector<Face>& faces, size_t vertex_count) {
  Topology t;
  t.neighbour.assign(faces.size(), {-1, -1, -1});
  t.edge_of.resize(faces.size());
  std::unordered_map<uint64_t, uint32_t> edge_ids;
  edge_ids.reserve(faces.size() * 2);
  std::vector<int32_t> some_face(vertex_count, -1);
  std::vector<uint32_t> incident(vertex_count, 0);
  for (size_t f = 0; f < faces.size(); ++f) {
    for (int k = 0; k < 3; ++k) {
      const uint32_t a = faces[f][k], b = faces[f][(k + 1) % 3];
      some_face[a] = static_cast<int32_t>(f);
      ++incident[a];
      const uint64_t key = (uint64_t(std::min(a, b)) << 32) | std::max(a, b);
      auto [it, inserted] = edge_ids.try_emplace(key, static_cast<uint32_t>(t.edges.size()));
      if (inserted) {
        t.edges.push_back(Edge{a, b, static_cast<int32_t>(f), k});
      } else {
        Edge& e = t.edges[it->second];
        if (e.f1 >= 0) fail("an edge is shared by more than two triangles (the mesh is not a manifold)");
        if (e.a == a) fail("two neighbouring triangles are wound in opposite directions");
        e.f1 = static_cast<int32_t>(f);
        t.neighbour[e.f0][e.k0] = static_cast<int32_t>(f);
        t.neighbour[f][k] = e.f0;
      }
      t.edge_of[f][k] = it->second;
    }
  }
  // One-rings: around a vertex, "next" crosses the edge leaving it and
  // "prev" the edge arriving at it. Every walk is bounded by the vertex's
  // triangle count, and must visit all of them (one fan per vertex).
  t.ring_start.assign(vertex_count + 1, 0);
  t.boundary.assign(vertex_count, 0);
  for (uint32_t v = 0; v < vertex_count; ++v) {
    t.ring_start[v] = static_cast<uint32_t>(t.ring.size());
    int32_t f = some_face[v];
    if (f < 0) continue;
    auto next_face = [&](int32_t face) { return t.neighbour[face][local_index(faces[face], v)]; };
    auto prev_face = [&](int32_t face) { return t.neighbour[face][(local_index(faces[face], v) + 2) % 3]; };
    uint32_t steps = 0;
    const int32_t start = f;
    do {
      f = next_face(f);
      if (++steps > incident[v]) fail("a vertex's triangles do not form one fan (the mesh is not a manifold)");
    } while (f >= 0 && f != start);
    uint32_t visited = 0;
    if (f == start) {
      do {
        t.ring.push_back(faces[f][(local_index(faces[f], v) + 1) % 3]);
        ++visited;
        f = next_face(f);
      } while (f != start);
    } else {
      t.boundary[v] = 1;
      f = start;
      for (int32_t g; (g = next_face(f)) >= 0;) f = g;
      t.ring.push_back(faces[f][(local_index(faces[f], v) + 1) % 3]);
      do {
        t.ring.push_back(faces[f][(local_index(faces[f], v) + 2) % 3]);
        ++visited;
        f = prev_face(f);
        if (visited > incident[v]) fail("a vertex's triangles do not form one fan (the mesh is not a manifold)");
      } while (f >= 0);
    }
    if (visited != incident[v]) fail("a vertex's triangles do not form one fan (the mesh is not a manifold)");
  }
  t.ring_start[vertex_count] = static_cast<uint32_t>(t.ring.size());
  return t;
}

double beta(uint32_t valence) { return valence == 3 ? 3.0 / 16.0 : 3.0 / (8.0 * valence); }
double loop_gamma(uint32_t valence) { return 1.0 / (valence + 3.0 / (8.0 * beta(valence))); }

// pbrt-v4's weightOneRing / weightBoundary.
Vec3 weight_one_ring(const Topology& t, const std::vector<Vec3>& p, uint32_t v, double b) {
  const uint32_t n = t.valence(v);
  const uint32_t* r = t.ring_of(v);
  Vec3 sum = static_cast<Float>(1.0 - n * b) * p[v];
  for (uint32_t i = 0; i < n; ++i) sum += static_cast<Float>(b) * p[r[i]];
  return sum;
}

Vec3 weight_boundary(const Topology& t, const std::vector<Vec3>& p, uint32_t v, double b) {
  const uint32_t n = t.valence(v);
  const uint32_t* r = t.ring_of(v);
  return static_cast<Float>(1.0 - 2.0 * b) * p[v] + static_cast<Float>(b) * (p[r[0]] + p[r[n - 1]]);
}

// The limit surface's normal at v: pbrt-v4's tangents S x T.
Vec3 limit_normal(const Topology& t, const std::vector<Vec3>& p, uint32_t v) {
  const uint32_t n = t.valence(v);
  const uint32_t* r = t.ring_of(v);
  Vec3 s(0.f), tan(0.f);
  if (!t.boundary[v]) {
    for (uint32_t j = 0; j < n; ++j) {
      const double angle = 2.0 * kPi * j / n;
      s += static_cast<Float>(std::cos(angle)) * p[r[j]];
      tan += static_cast<Float>(std::sin(angle)) * p[r[j]];
    }
  } else {
    s = p[r[n - 1]] - p[r[0]];
    if (n == 2) {
      tan = p[r[0]] + p[r[1]] - 2.f * p[v];
    } else if (n == 3) {
      tan = p[r[1]] - p[v];
    } else if (n == 4) {
      tan = -p[r[0]] + 2.f * p[r[1]] + 2.f * p[r[2]] - p[r[3]] - 2.f * p[v];
    } else {
      const double theta = kPi / (n - 1);
      tan = static_cast<Float>(std::sin(theta)) * (p[r[0]] + p[r[n - 1]]);
      for (uint32_t k = 1; k + 1 < n; ++k)
        tan += static_cast<Float>((2.0 * std::cos(theta) - 2.0) * std::sin(k * theta)) * p[r[k]];
      tan = -tan;
    }
  }
  return glm::cross(s, tan);
}

}  // namespace

SubdividedMesh loop_subdivide(const std::vector<Vec3>& p_in, const std::vector<uint32_t>& indices, int levels) {
  if (levels < 0) fail("\"levels\" must not be negative");
  std::vector<Vec3> p = p_in;
  std::vector<Face> faces;
  faces.reserve(indices.size() / 3);
  for (size_t i = 0; i + 2 < indices.size(); i += 3) {
    const Face f{indices[i], indices[i + 1], indices[i + 2]};
    if (f[0] == f[1] || f[1] == f[2] || f[2] == f[0]) fail("triangle " + std::to_string(i / 3) + " repeats a vertex");
    faces.push_back(f);
  }
  if (faces.empty()) fail("no triangles");
  if (levels > 13 || faces.size() > (kMaxSubdividedTriangles >> (2 * levels)))
    fail(std::to_string(levels) + " levels would make more than " + std::to_string(kMaxSubdividedTriangles) +
         " triangles");

  for (int level = 0; level < levels; ++level) {
    const Topology t = build_topology(faces, p.size());
    const uint32_t nv = static_cast<uint32_t>(p.size());
    std::vector<Vec3> next(nv + t.edges.size());
    // Even vertices: pbrt's rule (regular vertices have beta(6) = 1/16 anyway).
    for (uint32_t v = 0; v < nv; ++v) {
      if (t.valence(v) == 0) next[v] = p[v];  // referenced by no triangle
      else next[v] = t.boundary[v] ? weight_boundary(t, p, v, 1.0 / 8.0) : weight_one_ring(t, p, v, beta(t.valence(v)));
    }
    // Odd vertices, one per edge.
    for (size_t e = 0; e < t.edges.size(); ++e) {
      const Edge& edge = t.edges[e];
      if (edge.f1 < 0) {
        next[nv + e] = 0.5f * (p[edge.a] + p[edge.b]);
      } else {
        const uint32_t c = faces[edge.f0][(edge.k0 + 2) % 3];
        const Face& g = faces[edge.f1];
        const uint32_t d = g[0] != edge.a && g[0] != edge.b ? g[0] : g[1] != edge.a && g[1] != edge.b ? g[1] : g[2];
        next[nv + e] = 3.f / 8.f * (p[edge.a] + p[edge.b]) + 1.f / 8.f * (p[c] + p[d]);
      }
    }
    // Four children per face, in pbrt-v4's order and winding.
    std::vector<Face> children;
    children.reserve(faces.size() * 4);
    for (size_t f = 0; f < faces.size(); ++f) {
      const Face& v = faces[f];
      const uint32_t o0 = nv + t.edge_of[f][0], o1 = nv + t.edge_of[f][1], o2 = nv + t.edge_of[f][2];
      children.push_back({v[0], o0, o2});
      children.push_back({o0, v[1], o1});
      children.push_back({o2, o1, v[2]});
      children.push_back({o0, o1, o2});
    }
    p = std::move(next);
    faces = std::move(children);
  }

  // Limit positions, then normals from the limit positions' one-rings.
  const Topology t = build_topology(faces, p.size());
  SubdividedMesh out;
  out.p.resize(p.size());
  for (uint32_t v = 0; v < p.size(); ++v) {
    if (t.valence(v) == 0) out.p[v] = p[v];
    else out.p[v] = t.boundary[v] ? weight_boundary(t, p, v, 1.0 / 5.0) : weight_one_ring(t, p, v, loop_gamma(t.valence(v)));
  }
  out.n.resize(p.size(), Vec3(0.f));
  for (uint32_t v = 0; v < p.size(); ++v)
    if (t.valence(v) > 0) out.n[v] = limit_normal(t, out.p, v);
  out.indices.reserve(faces.size() * 3);
  for (const Face& f : faces) out.indices.insert(out.indices.end(), f.begin(), f.end());
  return out;
}

}  // namespace tessera
