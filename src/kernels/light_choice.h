// Which light next-event estimation samples at a point: pbrt-v4's light
// samplers ("lightsampler" of the Integrator), chosen per scene.
// - bvh (default): by importance at the point (light_bvh.h);
// - power: in proportion to emitted power, wherever the point is;
// - uniform: every light alike.
// The probability of a choice depends on the point for bvh, so a path keeps
// the point and normal where it sampled its last direction (MisMemory) for
// the MIS weight of a light that direction finds.
#pragma once

#include "scene_view.h"

namespace tessera {

// Where a light is chosen from: a scattering point and its shading normal
// (zero in a medium, where no cosine bounds what arrives).
struct LightQuery {
  Vec3 p{0.f};
  Vec3 n{0.f};
};

TESSERA_HOST_DEVICE inline Float light_choice_pmf(const SceneView& s, const LightQuery& q, uint32_t li) {
  switch (s.light_sampler) {
    case LightSamplerKind::Bvh: return s.light_bvh.pmf(q.p, q.n, li);
    case LightSamplerKind::Uniform: return s.num_lights > 0 ? 1.f / static_cast<Float>(s.num_lights) : 0.f;
    default: return s.light_select.discrete_pmf(li);
  }
}

// Chooses a light with one uniform number u; *pmf is its probability (0:
// no light can reach the point, nothing is to be sampled).
TESSERA_HOST_DEVICE inline uint32_t choose_light(const SceneView& s, const LightQuery& q, Float u, Float* pmf) {
  switch (s.light_sampler) {
    case LightSamplerKind::Bvh: return s.light_bvh.sample(q.p, q.n, u, pmf);
    case LightSamplerKind::Uniform: {
      const uint32_t n = s.num_lights;
      *pmf = n > 0 ? 1.f / static_cast<Float>(n) : 0.f;
      if (n == 0) return 0;
      return glm::min(static_cast<uint32_t>(u * static_cast<Float>(n)), n - 1);
    }
    default: return s.light_select.sample_discrete(u, pmf);
  }
}

}  // namespace tessera
