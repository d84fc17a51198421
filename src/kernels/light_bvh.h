// A bounding volume hierarchy over the lights, for choosing a light by its
// importance at a shading point (pbrt-v4's BVHLightSampler, after Conty
// Estevez & Kulla 2018). Every node bounds its lights' positions, emitted
// power and emission directions (a cone about w of half-angle theta_o, plus
// the spread theta_e past it). A light is drawn by walking down from the
// root, choosing each child in proportion to its importance; its probability
// is the product of the choices on its way. Built on the host
// (render/light_bvh_build.h), walked on either side.
#pragma once

#include "vecmath.h"

namespace tessera {

enum class LightSamplerKind : uint32_t { Bvh = 0, Power, Uniform };
// pbrt-v4's name of each ("lightsampler").
inline const char* light_sampler_name(LightSamplerKind k) {
  return k == LightSamplerKind::Power ? "power" : k == LightSamplerKind::Uniform ? "uniform" : "bvh";
}

// Node flags.
constexpr uint32_t kLightNodeLeaf = 1u;
constexpr uint32_t kLightNodeTwoSided = 2u;

// A node's bounds as the importance needs them: its box as centre, half
// diagonal and squared bounding-sphere radius (the box itself is not used).
struct LightBvhNode {
  Vec3 center{0.f};
  Float phi = 0.f;                // emitted power (pbrt-v4's bound: the spectrum's largest value)
  Vec3 w{0.f, 0.f, 1.f};          // emission cone axis
  Float cos_o = -1.f;             // cos theta_o: every emitter's normal lies within the cone
  Float sin_o = 0.f;
  Float cos_e = 0.f;              // cos theta_e: emission spreads at most this far past a normal
  Float half_diagonal = 0.f;      // pbrt-v4's floor of the squared distance (sic: a length)
  Float radius2 = 0.f;            // the box's bounding sphere, squared radius
  uint32_t child_or_light = 0;    // inner: the second child (the first is the next node); leaf: the light
  int32_t parent = -1;            // -1: the root
  uint32_t flags = 0;
  uint32_t pad = 0;
};

// Where a light is in the light sampler (SceneView::light_bvh_leaf): a leaf
// node, or one of these.
constexpr int32_t kLightUnbounded = -1;  // infinite and distant lights: chosen apart from the tree
constexpr int32_t kLightNeverChosen = -2;  // emits nothing

// cos(a - b) for angles in [0, pi], clamped to 1 where a < b (pbrt-v4's
// cosSubClamped).
TESSERA_HOST_DEVICE inline Float cos_sub_clamped(Float sin_a, Float cos_a, Float sin_b, Float cos_b) {
  return cos_a > cos_b ? 1.f : cos_a * cos_b + sin_a * sin_b;
}

// The importance of a node's lights at point p with shading normal n (zero
// in a medium): power over clamped squared distance, times the cosine bound
// of the emission towards p and (on surfaces) of the incidence at p. Zero
// only where no light of the node can send light to p.
TESSERA_HOST_DEVICE inline Float light_node_importance(const LightBvhNode& b, const Vec3& p, const Vec3& n) {
  const Vec3 to_p = p - b.center;
  const Float dist2 = glm::dot(to_p, to_p);
  // pbrt-v4 clamps the squared distance by half the box's diagonal; the
  // floor keeps a point light's importance finite at its own position.
  const Float d2 = glm::max(glm::max(dist2, b.half_diagonal), 1e-12f);
  const Vec3 wi = dist2 > 0.f ? to_p * glm::inversesqrt(dist2) : Vec3(0.f, 0.f, 1.f);
  Float cos_w = glm::dot(b.w, wi);
  if (b.flags & kLightNodeTwoSided) cos_w = glm::abs(cos_w);
  // The directions the box subtends from p (its bounding sphere's cone).
  const bool inside = dist2 <= b.radius2;
  const Float sin2_b = inside ? 0.f : b.radius2 / dist2;
  const Float cos_b = inside ? -1.f : safe_sqrt(1.f - sin2_b);
  // pbrt-v4's clamped differences of angles (cos_sub_clamped and its sine
  // counterpart), each sine taken only where the clamp does not decide.
  Float cos_x = 1.f, sin_x = 0.f;
  if (!(cos_w > b.cos_o)) {
    const Float sin_w = safe_sqrt(1.f - cos_w * cos_w);
    cos_x = cos_w * b.cos_o + sin_w * b.sin_o;
    sin_x = sin_w * b.cos_o - cos_w * b.sin_o;
  }
  const Float sin_b = glm::sqrt(sin2_b);
  const Float cos_p = cos_sub_clamped(sin_x, cos_x, sin_b, cos_b);
  if (cos_p <= b.cos_e) return 0.f;
  Float importance = b.phi * cos_p / d2;
  if (n.x != 0.f || n.y != 0.f || n.z != 0.f) {
    const Float cos_i = glm::abs(glm::dot(wi, n));
    if (!(cos_i > cos_b)) importance *= cos_i * cos_b + safe_sqrt(1.f - cos_i * cos_i) * sin_b;
  }
  return importance > 0.f ? importance : 0.f;
}

// The tree and the lights outside it, as SceneView carries them.
struct LightBvhView {
  const LightBvhNode* nodes = nullptr;  // nodes[0] is the root; none when no light is bounded
  uint32_t num_nodes = 0;
  const int32_t* leaf_of_light = nullptr;  // per light: its leaf, kLightUnbounded or kLightNeverChosen
  const uint32_t* unbounded = nullptr;     // the unbounded lights
  uint32_t num_unbounded = 0;

  // The chance of choosing among the unbounded lights rather than the tree
  // (pbrt-v4: the tree counts as one light among them).
  TESSERA_HOST_DEVICE Float p_unbounded() const {
    const Float trees = num_nodes > 0 ? 1.f : 0.f;
    return num_unbounded > 0 ? static_cast<Float>(num_unbounded) / (static_cast<Float>(num_unbounded) + trees) : 0.f;
  }

  // Chooses a light for point p, normal n (zero in a medium) with one
  // uniform number; *pmf = 0 where no light can reach p.
  TESSERA_HOST_DEVICE uint32_t sample(const Vec3& p, const Vec3& n, Float u, Float* pmf) const {
    const Float p_inf = p_unbounded();
    if (u < p_inf) {
      const uint32_t k = glm::min(static_cast<uint32_t>(u / p_inf * static_cast<Float>(num_unbounded)), num_unbounded - 1);
      *pmf = p_inf / static_cast<Float>(num_unbounded);
      return unbounded[k];
    }
    *pmf = 0.f;
    if (num_nodes == 0) return 0;
    u = glm::min((u - p_inf) / (1.f - p_inf), 0x1.fffffep-1f);
    Float prob = 1.f - p_inf;
    uint32_t k = 0;
    while (!(nodes[k].flags & kLightNodeLeaf)) {
      const uint32_t c1 = nodes[k].child_or_light;
      const Float i0 = light_node_importance(nodes[k + 1], p, n);
      const Float i1 = light_node_importance(nodes[c1], p, n);
      const Float sum = i0 + i1;
      if (!(sum > 0.f) || !(sum < kInfinity)) return 0;
      const Float p0 = i0 / sum;
      if (u < p0) {
        u = glm::min(u / p0, 0x1.fffffep-1f);
        prob *= p0;
        k = k + 1;
      } else {
        const Float p1 = 1.f - p0;
        u = glm::min((u - p0) / p1, 0x1.fffffep-1f);
        prob *= i1 / sum;
        k = c1;
      }
    }
    if (k == 0 && !(light_node_importance(nodes[0], p, n) > 0.f)) return 0;
    *pmf = prob;
    return nodes[k].child_or_light;
  }

  // The probability that sample() chooses light li at (p, n): the choices
  // on the way from its leaf up to the root.
  TESSERA_HOST_DEVICE Float pmf(const Vec3& p, const Vec3& n, uint32_t li) const {
    const int32_t leaf = leaf_of_light[li];
    if (leaf == kLightUnbounded) return p_unbounded() / static_cast<Float>(num_unbounded);
    if (leaf < 0) return 0.f;
    Float prob = 1.f - p_unbounded();
    int32_t k = leaf;
    if (k == 0) return light_node_importance(nodes[0], p, n) > 0.f ? prob : 0.f;
    while (k > 0) {
      const int32_t parent = nodes[k].parent;
      const uint32_t c1 = nodes[parent].child_or_light;
      const Float i0 = light_node_importance(nodes[parent + 1], p, n);
      const Float i1 = light_node_importance(nodes[c1], p, n);
      const Float sum = i0 + i1;
      if (!(sum > 0.f) || !(sum < kInfinity)) return 0.f;
      prob *= (static_cast<uint32_t>(k) == c1 ? i1 : i0) / sum;
      k = parent;
    }
    return prob;
  }
};

}  // namespace tessera
