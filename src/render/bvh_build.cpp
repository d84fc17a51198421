#include "render/bvh_build.h"

#include <algorithm>
#include <cmath>

namespace tessera {
namespace {

struct Box {
  Vec3 lo{kInfinity}, hi{-kInfinity};
  void grow(const Vec3& p) {
    lo = glm::min(lo, p);
    hi = glm::max(hi, p);
  }
  void grow(const Box& b) {
    lo = glm::min(lo, b.lo);
    hi = glm::max(hi, b.hi);
  }
  bool empty() const { return !(lo.x <= hi.x); }
  Float area() const {
    if (empty()) return 0.f;
    const Vec3 e = hi - lo;
    return 2.f * (e.x * e.y + e.y * e.z + e.z * e.x);
  }
};

struct Prim {
  Box box;
  Vec3 centre;
  uint32_t triangle;
};

constexpr int kBins = 16;

class Builder {
 public:
  Builder(std::vector<Prim>& prims, BvhBuild& out) : prims_(prims), out_(out) {}

  // Builds the subtree of prims [begin, end) at out_.nodes[index].
  void build(uint32_t index, size_t begin, size_t end, int depth) {
    out_.depth = std::max(out_.depth, depth);
    Box box, centres;
    for (size_t i = begin; i < end; ++i) {
      box.grow(prims_[i].box);
      centres.grow(prims_[i].centre);
    }
    const size_t count = end - begin;
    int axis = -1;
    size_t mid = begin;
    if (count > 1 && depth + 1 < kBvhStackSize - 1) {
      if (!sah_split(box, centres, begin, end, &axis, &mid) && count > static_cast<size_t>(kBvhMaxLeaf)) {
        // No split pays (or all centres coincide): halves by the widest centre axis.
        const Vec3 e = centres.hi - centres.lo;
        axis = e.x > e.y ? (e.x > e.z ? 0 : 2) : (e.y > e.z ? 1 : 2);
        mid = begin + count / 2;
        std::nth_element(prims_.begin() + begin, prims_.begin() + mid, prims_.begin() + end,
                         [axis](const Prim& a, const Prim& b) { return a.centre[axis] < b.centre[axis]; });
      }
    }
    BvhNode& node = out_.nodes[index];
    node.lo = box.lo;
    node.hi = box.hi;
    if (axis < 0) {
      node.offset = static_cast<uint32_t>(out_.triangles.size());
      node.count_axis = static_cast<uint32_t>(count);
      for (size_t i = begin; i < end; ++i) out_.triangles.push_back(prims_[i].triangle);
      return;
    }
    node.count_axis = kBvhInner | static_cast<uint32_t>(axis);
    const uint32_t left = static_cast<uint32_t>(out_.nodes.size());
    out_.nodes.emplace_back();
    build(left, begin, mid, depth + 1);
    const uint32_t right = static_cast<uint32_t>(out_.nodes.size());
    out_.nodes.emplace_back();
    out_.nodes[index].offset = right;  // `node` may have moved with the vector
    build(right, mid, end, depth + 1);
  }

 private:
  // The cheapest binned SAH split of [begin, end), partitioned in place;
  // false when none beats a leaf (for at most kBvhMaxLeaf triangles) or the
  // centres do not spread.
  bool sah_split(const Box& box, const Box& centres, size_t begin, size_t end, int* axis_out, size_t* mid_out) {
    const size_t count = end - begin;
    Float best_cost = kInfinity;
    int best_axis = -1, best_bin = -1;
    for (int axis = 0; axis < 3; ++axis) {
      const Float lo = centres.lo[axis], extent = centres.hi[axis] - lo;
      if (!(extent > 0.f)) continue;
      Box bins[kBins];
      size_t counts[kBins] = {};
      for (size_t i = begin; i < end; ++i) {
        const int b = std::min(kBins - 1, static_cast<int>(kBins * ((prims_[i].centre[axis] - lo) / extent)));
        bins[b].grow(prims_[i].box);
        ++counts[b];
      }
      Float right_area[kBins];
      size_t right_count[kBins];
      Box acc;
      size_t n = 0;
      for (int b = kBins - 1; b > 0; --b) {
        acc.grow(bins[b]);
        n += counts[b];
        right_area[b] = acc.area();
        right_count[b] = n;
      }
      acc = Box();
      n = 0;
      for (int b = 0; b < kBins - 1; ++b) {
        acc.grow(bins[b]);
        n += counts[b];
        if (n == 0 || right_count[b + 1] == 0) continue;
        const Float cost = acc.area() * static_cast<Float>(n) + right_area[b + 1] * static_cast<Float>(right_count[b + 1]);
        if (cost < best_cost) {
          best_cost = cost;
          best_axis = axis;
          best_bin = b;
        }
      }
    }
    if (best_axis < 0) return false;
    // Traversal step ~ 1 triangle test: a leaf costs count x its area.
    const Float leaf_cost = box.area() * static_cast<Float>(count);
    if (count <= static_cast<size_t>(kBvhMaxLeaf) && !(best_cost + box.area() < leaf_cost)) return false;
    const Float lo = centres.lo[best_axis], extent = centres.hi[best_axis] - lo;
    auto in_left = [&](const Prim& p) {
      return std::min(kBins - 1, static_cast<int>(kBins * ((p.centre[best_axis] - lo) / extent))) <= best_bin;
    };
    const auto split = std::partition(prims_.begin() + begin, prims_.begin() + end, in_left);
    const size_t mid = static_cast<size_t>(split - prims_.begin());
    if (mid == begin || mid == end) return false;
    *axis_out = best_axis;
    *mid_out = mid;
    return true;
  }

  std::vector<Prim>& prims_;
  BvhBuild& out_;
};

}  // namespace

namespace {

// The leaf items of one tree: triangles [first, first + count) in their own space.
void add_triangles(const SceneView& s, uint32_t first, uint32_t count, std::vector<Prim>& prims) {
  for (uint32_t t = first; t < first + count; ++t) {
    Prim p;
    p.triangle = t;
    const uint32_t* idx = s.indices + 3 * static_cast<size_t>(t);
    for (int k = 0; k < 3; ++k) {
      p.box.grow(s.positions[idx[k]]);
      if (s.positions_end) p.box.grow(s.positions_end[idx[k]]);
    }
    p.centre = 0.5f * (p.box.lo + p.box.hi);
    if (!is_finite(p.centre)) continue;  // the loader refuses non-finite vertices; never bin one
    prims.push_back(p);
  }
}

// An instance as a top-level item: its prototype's box placed at both ends
// of the transform interval (a vertex moves on a straight line between its
// two placements, which the union of both boxes holds).
bool add_instance(const ObjectInstance& inst, uint32_t index, const Box& object, std::vector<Prim>& prims) {
  if (object.empty()) return false;
  Prim p;
  p.triangle = kBvhInstanceItem | index;
  for (const Affine* a : {&inst.render_from_object, &inst.render_from_object_end})
    for (int c = 0; c < 8; ++c)
      p.box.grow(apply_point(*a, Vec3(c & 1 ? object.hi.x : object.lo.x, c & 2 ? object.hi.y : object.lo.y,
                                      c & 4 ? object.hi.z : object.lo.z)));
  p.centre = 0.5f * (p.box.lo + p.box.hi);
  if (!is_finite(p.centre)) return false;
  prims.push_back(p);
  return true;
}

// Appends a tree over prims; its root's index, or kBvhNoRoot for none.
uint32_t add_tree(std::vector<Prim>& prims, BvhBuild& out) {
  if (prims.empty()) return kBvhNoRoot;
  const uint32_t root = static_cast<uint32_t>(out.nodes.size());
  out.nodes.emplace_back();
  Builder(prims, out).build(root, 0, prims.size(), 0);
  return root;
}

}  // namespace

BvhBuild build_bvh(const SceneView& s) {
  BvhBuild out;
  out.nodes.reserve(2 * static_cast<size_t>(s.num_triangles) + 2 * static_cast<size_t>(s.num_instances));
  out.triangles.reserve(s.num_triangles + s.num_instances);
  // The prototypes' trees first (their boxes bound the instances); the
  // top-level tree then goes to the front, as the traversal starts at node 0.
  std::vector<Box> object_boxes(s.num_prototypes);
  std::vector<uint32_t> roots(s.num_prototypes, kBvhNoRoot);
  BvhBuild objects;
  for (uint32_t i = 0; i < s.num_prototypes; ++i) {
    std::vector<Prim> prims;
    add_triangles(s, s.prototypes[i].first_triangle, s.prototypes[i].num_triangles, prims);
    for (const Prim& p : prims) object_boxes[i].grow(p.box);
    roots[i] = add_tree(prims, objects);
  }
  std::vector<Prim> top;
  top.reserve(s.num_world_triangles + s.num_instances);
  add_triangles(s, 0, s.num_world_triangles, top);
  for (uint32_t i = 0; i < s.num_instances; ++i) add_instance(s.instances[i], i, object_boxes[s.instances[i].prototype], top);
  if (top.empty()) return out;
  add_tree(top, out);
  // Move the prototypes' trees behind it: node offsets and leaf offsets shift.
  const uint32_t node_shift = static_cast<uint32_t>(out.nodes.size());
  const uint32_t item_shift = static_cast<uint32_t>(out.triangles.size());
  for (BvhNode n : objects.nodes) {
    n.offset += (n.count_axis & kBvhInner) ? node_shift : item_shift;
    out.nodes.push_back(n);
  }
  out.triangles.insert(out.triangles.end(), objects.triangles.begin(), objects.triangles.end());
  for (uint32_t& r : roots)
    if (r != kBvhNoRoot) r += node_shift;
  out.prototype_roots = std::move(roots);
  out.depth = std::max(out.depth, objects.depth);
  return out;
}

}  // namespace tessera
