// A bounding volume hierarchy over the scene's triangles, built on the host
// (render/bvh_build.h) and traversed by code that g++ and nvcc compile
// alike: the ray queries of the portable backend, on the CPU (where tests
// compare it with Embree) and on the GPU. Ours, because the GPU needs one
// (Embree is CPU-only, OptiX is not in Debian); its rules are Embree's:
// hits at t in (0, tmax], the same candidate filter (hit_filter.h), moving
// triangles interpolated linearly at the ray's time, and the same
// barycentrics (b1, b2 of vertices 1 and 2), so the integrator's ray
// offsets and surface reconstruction serve both.
#pragma once

#include "hit_filter.h"
#include "ray_guard.h"
#include "surface.h"

namespace tessera {

// 32 bytes. Inner nodes: the left child follows the node, `offset` is the
// right child; `count_axis` is kBvhInner | the split axis. Leaves: `offset`
// indexes BvhView::triangles, `count_axis` is the item count (>= 1).
struct BvhNode {
  Vec3 lo{0.f};
  uint32_t offset = 0;
  Vec3 hi{0.f};
  uint32_t count_axis = 0;
};

constexpr uint32_t kBvhInner = 0x80000000u;
// A leaf item of the top-level tree that is an instance (its index in the
// low bits), not a triangle: two levels, as Embree's instances.
constexpr uint32_t kBvhInstanceItem = 0x80000000u;
constexpr uint32_t kBvhNoRoot = 0xffffffffu;
// The traversal stack (one per level); the builder keeps each tree shallower than this.
constexpr int kBvhStackSize = 64;

// One node array holds the top-level tree (root 0: the world's triangles
// and the instances) and each prototype's tree over its own triangles.
struct BvhView {
  const BvhNode* nodes = nullptr;
  const uint32_t* triangles = nullptr;  // leaf items, leaf by leaf
  uint32_t num_nodes = 0;
  uint32_t num_triangles = 0;  // entries of triangles (triangles with non-finite bounds are left out)
  const uint32_t* prototype_roots = nullptr;  // per prototype, its root in nodes (kBvhNoRoot: nothing to hit)
  uint32_t num_prototypes = 0;
};

namespace bvh_detail {

// The ray's entry and exit of a box, as pbrt-v4's Bounds3::IntersectP: the
// exit widened by 2 gamma(3) so that rounding never culls a box the ray
// grazes; NaN (0 * inf on a slab's plane) is dropped by fminf/fmaxf.
TESSERA_HOST_DEVICE inline bool hits_box(const Vec3& lo, const Vec3& hi, const Vec3& o, const Vec3& inv_d, Float tmax) {
  constexpr Float kWiden = 1.f + 2.f * (3.f * 0x1p-24f) / (1.f - 3.f * 0x1p-24f);
  Float t0 = 0.f, t1 = tmax;
  for (int a = 0; a < 3; ++a) {
    Float near = (lo[a] - o[a]) * inv_d[a], far = (hi[a] - o[a]) * inv_d[a];
    if (near > far) {
      const Float tmp = near;
      near = far;
      far = tmp;
    }
    far *= kWiden;
    t0 = fmaxf(t0, near);
    t1 = fminf(t1, far);
    if (t0 > t1) return false;
  }
  return true;
}

// Watertight ray/triangle intersection (Woop, Benthin and Wald 2013): the
// edge functions of the triangle sheared into ray space, redone in double
// where one is exactly 0, so a ray through a shared edge or vertex meets
// exactly one of its triangles (on the host; nvcc's contracted
// multiply-adds may break ties differently). On a hit in (0, tmax]: *t and the
// barycentrics of vertices 1 and 2.
TESSERA_HOST_DEVICE inline bool hits_triangle(const Vec3& p0, const Vec3& p1, const Vec3& p2, const Vec3& o,
                                              const Vec3& d, Float tmax, Float* t, Float* b1, Float* b2) {
  const Vec3 ad = abs3(d);
  int kz = ad.x > ad.y ? (ad.x > ad.z ? 0 : 2) : (ad.y > ad.z ? 1 : 2);
  int kx = kz == 2 ? 0 : kz + 1, ky = kx == 2 ? 0 : kx + 1;
  if (d[kz] < 0.f) {
    const int tmp = kx;
    kx = ky;
    ky = tmp;
  }
  if (d[kz] == 0.f) return false;
  const Float sx = d[kx] / d[kz], sy = d[ky] / d[kz], sz = 1.f / d[kz];
  const Vec3 a = p0 - o, b = p1 - o, c = p2 - o;
  const Float ax = a[kx] - sx * a[kz], ay = a[ky] - sy * a[kz];
  const Float bx = b[kx] - sx * b[kz], by = b[ky] - sy * b[kz];
  const Float cx = c[kx] - sx * c[kz], cy = c[ky] - sy * c[kz];
  Float u = cx * by - cy * bx, v = ax * cy - ay * cx, w = bx * ay - by * ax;
  if (u == 0.f || v == 0.f || w == 0.f) {
    u = static_cast<Float>(double(cx) * double(by) - double(cy) * double(bx));
    v = static_cast<Float>(double(ax) * double(cy) - double(ay) * double(cx));
    w = static_cast<Float>(double(bx) * double(ay) - double(by) * double(ax));
  }
  if ((u < 0.f || v < 0.f || w < 0.f) && (u > 0.f || v > 0.f || w > 0.f)) return false;
  const Float det = u + v + w;
  if (det == 0.f) return false;
  const Float scaled_t = u * (sz * a[kz]) + v * (sz * b[kz]) + w * (sz * c[kz]);
  // t = scaled_t / det in (0, tmax), compared without the division.
  if (det > 0.f ? (scaled_t <= 0.f || scaled_t > tmax * det) : (scaled_t >= 0.f || scaled_t < tmax * det)) return false;
  const Float inv = 1.f / det;
  *t = scaled_t * inv;
  *b1 = v * inv;
  *b2 = w * inv;
  return *t > 0.f && *t <= tmax;
}

}  // namespace bvh_detail

namespace bvh_detail {

struct TreeRay {
  Vec3 o, d;
  int32_t instance;  // whose prototype's space o, d are in; -1: render space
};

// The closest hit in (0, *tmax] of one tree, or with any_hit the first one
// found (shadow rays); *tmax shrinks to each closer hit. Candidates the
// scene filters (alpha, one-way faces) are skipped. The top-level tree
// (kTop) descends into the instances its leaves name.
template <bool kTop>
TESSERA_HOST_DEVICE inline bool trace_tree(const BvhView& bvh, const SceneView& s, uint32_t root, const TreeRay& r,
                                           Float* tmax, Float time, bool any_hit, TraceHit* hit);

// An instance's prototype, with the ray carried into its space (t unchanged).
TESSERA_HOST_DEVICE inline bool trace_instance(const BvhView& bvh, const SceneView& s, uint32_t instance, const TreeRay& r,
                                               Float* tmax, Float time, bool any_hit, TraceHit* hit) {
  const ObjectInstance& inst = s.instances[instance];
  const uint32_t root = bvh.prototype_roots[inst.prototype];
  if (root == kBvhNoRoot) return false;
  const Affine to_object = placement_at(inst, time).object_from_render;
  const TreeRay local{apply_point(to_object, r.o), apply_vector(to_object, r.d), static_cast<int32_t>(instance)};
  return trace_tree<false>(bvh, s, root, local, tmax, time, any_hit, hit);
}

template <bool kTop>
TESSERA_HOST_DEVICE inline bool trace_tree(const BvhView& bvh, const SceneView& s, uint32_t root, const TreeRay& r,
                                           Float* tmax, Float time, bool any_hit, TraceHit* hit) {
  const Vec3 &o = r.o, &d = r.d;
  const Vec3 inv_d(1.f / d.x, 1.f / d.y, 1.f / d.z);
  const bool filtered = s.triangle_alpha || s.has_one_way_faces;
  uint32_t stack[kBvhStackSize];
  int top = 0;
  uint32_t node = root;
  bool found = false;
  for (;;) {
    const BvhNode& n = bvh.nodes[node];
    if (hits_box(n.lo, n.hi, o, inv_d, *tmax)) {
      if (n.count_axis & kBvhInner) {
        // Nearer child first: the far one waits on the stack.
        const uint32_t axis = n.count_axis & 3u;
        const bool right_first = d[axis] < 0.f;
        // The builder keeps leaves above kBvhStackSize - 1 levels, so the stack never fills.
        if (top < kBvhStackSize) stack[top++] = right_first ? node + 1 : n.offset;
        node = right_first ? n.offset : node + 1;
        continue;
      }
      for (uint32_t i = 0; i < n.count_axis; ++i) {
        const uint32_t tri = bvh.triangles[n.offset + i];
        if constexpr (kTop) {
          if (tri & kBvhInstanceItem) {
            if (trace_instance(bvh, s, tri & ~kBvhInstanceItem, r, tmax, time, any_hit, hit)) {
              found = true;
              if (any_hit) return true;
            }
            continue;
          }
        }
        Vec3 p0, p1, p2;
        triangle_vertices_at(s, tri, time, &p0, &p1, &p2);
        Float t, b1, b2;
        if (!hits_triangle(p0, p1, p2, o, d, *tmax, &t, &b1, &b2)) continue;
        if (filtered && hit_ignored(s, tri, r.instance, b1, b2, o, d, time)) continue;
        *tmax = t;
        hit->t = t;
        hit->triangle = tri;
        hit->b1 = b1;
        hit->b2 = b2;
        hit->instance = r.instance;
        found = true;
        if (any_hit) return true;
      }
    }
    if (top == 0) return found;
    node = stack[--top];
  }
}

}  // namespace bvh_detail

// The closest hit in (0, tmax], or with any_hit the first one found (shadow
// rays), on the world's triangles and every instance's.
TESSERA_HOST_DEVICE TESSERA_DEVICE_NOINLINE inline bool bvh_trace(const BvhView& bvh, const SceneView& s, const Vec3& o, const Vec3& d,
                                          Float tmax, Float time, bool any_hit, TraceHit* hit) {
  if (bvh.num_nodes == 0 || !(tmax > 0.f)) return false;
  return bvh_detail::trace_tree<true>(bvh, s, 0, bvh_detail::TreeRay{o, d, -1}, &tmax, time, any_hit, hit);
}

// The ray query interface the integrator takes (EmbreeTracer's), over a
// BVH, for the rays Embree takes (ray_guard.h: a non-finite ray would pass
// every box, as NaN slabs are dropped).
struct BvhTracer {
  BvhView bvh;
  const SceneView* scene = nullptr;
  uint64_t* untraceable = nullptr;  // where refused rays are counted; null: not counted

  TESSERA_HOST_DEVICE bool intersect(const Vec3& o, const Vec3& d, Float tmax, TraceHit* hit, Float time = 0.f) const {
    if (!ray_traceable(o, d, tmax)) return refuse_ray(untraceable, false);
    return bvh_trace(bvh, *scene, o, d, tmax, time, false, hit);
  }
  TESSERA_HOST_DEVICE bool occluded(const Vec3& o, const Vec3& d, Float tmax, Float time = 0.f) const {
    if (!ray_traceable(o, d, tmax)) return refuse_ray(untraceable, true);
    TraceHit hit;
    return bvh_trace(bvh, *scene, o, d, tmax, time, true, &hit);
  }
};

}  // namespace tessera
