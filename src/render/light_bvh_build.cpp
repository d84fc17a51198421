#include "render/light_bvh_build.h"

#include <algorithm>
#include <array>
#include <limits>
#include <cmath>

namespace tessera {

namespace {

constexpr double kPiD = 3.14159265358979323846;
// Cones are widened by this angle when stored in floats, so that rounding
// never puts a direction a light emits into outside its node's cone.
constexpr double kConeSlack = 1e-3;

using DVec3 = glm::dvec3;

// The bounds the build works with, in double.
struct Bound {
  DVec3 lo{0.0}, hi{0.0};
  double phi = 0.0;
  DVec3 w{0.0, 0.0, 1.0};
  double cos_o = 1.0, cos_e = 1.0;
  bool two_sided = false;
  DVec3 centroid() const { return 0.5 * (lo + hi); }
};

double safe_acos(double c) { return std::acos(std::clamp(c, -1.0, 1.0)); }

// The smallest cone found by pbrt-v4's rule that holds cones (wa, cos_a) and
// (wb, cos_b); sets *w and returns its cosine.
double cone_union(const DVec3& wa, double cos_a, const DVec3& wb, double cos_b, DVec3* w) {
  const double ta = safe_acos(cos_a), tb = safe_acos(cos_b);
  const double td = safe_acos(glm::dot(wa, wb));
  if (std::min(td + tb, kPiD) <= ta) { *w = wa; return cos_a; }
  if (std::min(td + ta, kPiD) <= tb) { *w = wb; return cos_b; }
  const double to = 0.5 * (ta + td + tb);
  const DVec3 axis = glm::cross(wa, wb);
  const double axis_len = glm::length(axis);
  if (to >= kPiD || !(axis_len > 0.0)) { *w = wa; return -1.0; }
  // Rotate wa towards wb by to - ta (Rodrigues' formula).
  const DVec3 k = axis / axis_len;
  const double tr = to - ta;
  *w = glm::normalize(wa * std::cos(tr) + glm::cross(k, wa) * std::sin(tr) + k * glm::dot(k, wa) * (1.0 - std::cos(tr)));
  return std::cos(to);
}

Bound merge(const Bound& a, const Bound& b) {
  if (a.phi == 0.0) return b;
  if (b.phi == 0.0) return a;
  Bound m;
  m.lo = glm::min(a.lo, b.lo);
  m.hi = glm::max(a.hi, b.hi);
  m.phi = a.phi + b.phi;
  m.cos_o = cone_union(a.w, a.cos_o, b.w, b.cos_o, &m.w);
  m.cos_e = std::min(a.cos_e, b.cos_e);
  m.two_sided = a.two_sided || b.two_sided;
  return m;
}

// pbrt-v4's EvaluateCost: power x the solid angle measure of the emission
// cone x surface area, with a penalty for splitting along a short axis.
double split_cost(const Bound& b, const DVec3& extent, int dim) {
  const double to = safe_acos(b.cos_o), te = safe_acos(b.cos_e);
  const double tw = std::min(to + te, kPiD);
  const double sin_o = std::sqrt(std::max(0.0, 1.0 - b.cos_o * b.cos_o));
  const double m_omega = 2.0 * kPiD * (1.0 - b.cos_o) +
                         kPiD / 2.0 * (2.0 * tw * sin_o - std::cos(to - 2.0 * tw) - 2.0 * to * sin_o + b.cos_o);
  const double kr = std::max({extent.x, extent.y, extent.z}) / extent[dim];
  const DVec3 d = b.hi - b.lo;
  const double area = 2.0 * (d.x * d.y + d.y * d.z + d.z * d.x);
  return b.phi * m_omega * kr * area;
}

struct Builder {
  const std::vector<Bound>& bounds;
  std::vector<uint32_t>& order;  // light indices, partitioned in place
  LightBvh& out;

  // The split of order[start, end): the index where the second half starts.
  size_t split(size_t start, size_t end) {
    // The boxes of the lights and of their centroids (the cones are not needed here).
    DVec3 lo(std::numeric_limits<double>::max()), hi(-std::numeric_limits<double>::max());
    DVec3 c_lo = lo, c_hi = hi;
    for (size_t i = start; i < end; ++i) {
      const Bound& b = bounds[order[i]];
      lo = glm::min(lo, b.lo);
      hi = glm::max(hi, b.hi);
      c_lo = glm::min(c_lo, b.centroid());
      c_hi = glm::max(c_hi, b.centroid());
    }
    constexpr int kBuckets = 12;
    double best = std::numeric_limits<double>::infinity();
    int best_dim = -1, best_bucket = -1;
    const DVec3 extent = hi - lo;
    auto bucket_of = [&](const Bound& b, int dim) {
      const int k = static_cast<int>(kBuckets * (b.centroid()[dim] - c_lo[dim]) / (c_hi[dim] - c_lo[dim]));
      return std::clamp(k, 0, kBuckets - 1);
    };
    for (int dim = 0; dim < 3; ++dim) {
      if (!(c_hi[dim] > c_lo[dim]) || !(extent[dim] > 0.0)) continue;
      std::array<Bound, kBuckets> bucket{};
      for (size_t i = start; i < end; ++i) {
        const Bound& b = bounds[order[i]];
        const int k = bucket_of(b, dim);
        bucket[k] = merge(bucket[k], b);
      }
      // The buckets below a split are merged in one sweep (the same unions in
      // the same order as merging each range anew); those above each split
      // left to right, as pbrt-v4 does (cone unions are not associative).
      Bound below;
      for (int s = 0; s < kBuckets - 1; ++s) {
        below = merge(below, bucket[s]);
        if (s == 0) continue;  // pbrt-v4 starts at 1
        Bound above;
        for (int j = s + 1; j < kBuckets; ++j) above = merge(above, bucket[j]);
        const double cost = split_cost(below, extent, dim) + split_cost(above, extent, dim);
        if (cost > 0.0 && cost < best) {
          best = cost;
          best_dim = dim;
          best_bucket = s;
        }
      }
    }
    size_t mid = (start + end) / 2;
    if (best_dim >= 0) {
      const auto first = order.begin() + static_cast<std::ptrdiff_t>(start);
      const auto last = order.begin() + static_cast<std::ptrdiff_t>(end);
      const auto at = std::stable_partition(first, last, [&](uint32_t li) { return bucket_of(bounds[li], best_dim) <= best_bucket; });
      mid = static_cast<size_t>(at - order.begin());
      if (mid == start || mid == end) mid = (start + end) / 2;
    }
    return mid;
  }

  // Builds the subtree of order[start, end) under `parent`; returns its bounds.
  Bound build(size_t start, size_t end, int32_t parent) {
    const int32_t index = static_cast<int32_t>(out.nodes.size());
    out.nodes.emplace_back();
    out.nodes[static_cast<size_t>(index)].parent = parent;
    Bound b;
    uint32_t flags = 0, child_or_light = 0;
    if (end - start == 1) {
      child_or_light = order[start];
      b = bounds[child_or_light];
      flags = kLightNodeLeaf;
      out.leaf_of_light[child_or_light] = index;
    } else {
      const size_t mid = split(start, end);
      const Bound b0 = build(start, mid, index);
      child_or_light = static_cast<uint32_t>(out.nodes.size());
      const Bound b1 = build(mid, end, index);
      b = merge(b0, b1);
    }
    LightBvhNode& n = out.nodes[static_cast<size_t>(index)];
    const DVec3 diagonal = b.hi - b.lo;
    n.center = Vec3(0.5 * (b.lo + b.hi));
    n.half_diagonal = static_cast<Float>(0.5 * glm::length(diagonal));
    // Rounded up: the sphere must hold the box in float too.
    n.radius2 = static_cast<Float>(0.25 * glm::dot(diagonal, diagonal) * (1.0 + 1e-5));
    n.phi = static_cast<Float>(b.phi);
    n.w = Vec3(glm::normalize(b.w));
    const double theta_o = b.cos_o <= -1.0 ? kPiD : std::min(safe_acos(b.cos_o) + kConeSlack, kPiD);
    n.cos_o = static_cast<Float>(std::cos(theta_o));
    n.sin_o = static_cast<Float>(std::sin(theta_o));
    n.cos_e = static_cast<Float>(std::cos(std::min(safe_acos(b.cos_e) + kConeSlack, kPiD)));
    n.child_or_light = child_or_light;
    n.flags = flags | (b.two_sided ? kLightNodeTwoSided : 0u);
    return b;
  }
};

}  // namespace

LightBounds bounds_of_light(const Light& l, const LightGeometry& g, Float image_mean) {
  LightBounds b;
  const double power = max_component(l.L) * static_cast<double>(image_mean);
  switch (l.type) {
    case LightType::Distant:
    case LightType::Infinite: b.unbounded = true; return b;
    case LightType::Area: {
      const uint32_t* idx = g.indices + 3 * static_cast<size_t>(l.triangle);
      b.lo = b.hi = g.positions[idx[0]];
      bool moves = false;
      for (int k = 0; k < 3; ++k) {
        b.lo = glm::min(b.lo, g.positions[idx[k]]);
        b.hi = glm::max(b.hi, g.positions[idx[k]]);
        if (g.positions_end) {
          b.lo = glm::min(b.lo, g.positions_end[idx[k]]);
          b.hi = glm::max(b.hi, g.positions_end[idx[k]]);
          moves |= g.positions_end[idx[k]] != g.positions[idx[k]];
        }
      }
      b.phi = power * l.area * kPiD * (l.two_sided ? 2.0 : 1.0);
      b.w = g.face_normals[l.triangle];
      b.cos_o = 1.0;
      b.cos_e = 0.0;  // cos(pi / 2)
      b.two_sided = l.two_sided;
      // Vertex normals decide the emitting side (make_surface_hit): flip
      // where they all disagree with the face; where they differ among
      // themselves, or the triangle turns as it moves, either side may emit.
      const TriangleInfo& info = g.triangles[l.triangle];
      if (info.flags & kTriHasNormals) {
        int agree = 0, disagree = 0;
        for (int k = 0; k < 3; ++k) {
          const Float d = glm::dot(g.normals[idx[k]], b.w);
          agree += d > 0.f;
          disagree += d < 0.f;
        }
        if (agree == 0 && disagree > 0) b.w = -b.w;
        else if (disagree > 0) b.two_sided = true;
      }
      if (moves) b.cos_o = -1.0;
      return b;
    }
    case LightType::Spot: {
      b.lo = b.hi = l.position;
      b.phi = 4.0 * kPiD * power;
      b.w = l.direction;
      b.cos_o = l.cos_falloff_start;
      b.cos_e = std::cos(std::max(0.0, safe_acos(l.cos_falloff_end) - safe_acos(l.cos_falloff_start)));
      return b;
    }
    default:  // point, goniometric, projection: every direction
      b.lo = b.hi = l.position;
      b.phi = 4.0 * kPiD * power;
      b.cos_o = -1.0;
      b.cos_e = 0.0;
      return b;
  }
}

LightBvh build_light_bvh(const std::vector<LightBounds>& lights) {
  LightBvh out;
  out.leaf_of_light.assign(lights.size(), kLightNeverChosen);
  std::vector<Bound> bounds(lights.size());
  std::vector<uint32_t> order;
  for (uint32_t i = 0; i < lights.size(); ++i) {
    const LightBounds& l = lights[i];
    if (l.unbounded) {
      out.leaf_of_light[i] = kLightUnbounded;
      out.unbounded.push_back(i);
      continue;
    }
    if (!(l.phi > 0.0) || !std::isfinite(l.phi)) continue;
    Bound& b = bounds[i];
    b.lo = DVec3(l.lo);
    b.hi = DVec3(l.hi);
    b.phi = l.phi;
    const double len = glm::length(DVec3(l.w));
    b.w = len > 0.0 ? DVec3(l.w) / len : DVec3(0.0, 0.0, 1.0);
    b.cos_o = len > 0.0 ? l.cos_o : -1.0;
    b.cos_e = l.cos_e;
    b.two_sided = l.two_sided;
    order.push_back(i);
  }
  if (order.empty()) return out;
  out.nodes.reserve(2 * order.size() - 1);
  Builder{bounds, order, out}.build(0, order.size(), -1);
  return out;
}

LightBvhView LightBvh::view() const {
  LightBvhView v;
  v.nodes = nodes.empty() ? nullptr : nodes.data();
  v.num_nodes = static_cast<uint32_t>(nodes.size());
  v.leaf_of_light = leaf_of_light.empty() ? nullptr : leaf_of_light.data();
  v.unbounded = unbounded.empty() ? nullptr : unbounded.data();
  v.num_unbounded = static_cast<uint32_t>(unbounded.size());
  return v;
}

}  // namespace tessera
