// pbrt-v4's alpha cutouts: a hit on a surface whose alpha is a < 1 is ignored
// with probability 1 - a. The decision is a hash of the ray and the triangle,
// as pbrt-v4 hashes the ray: deterministic per ray, independent between the
// layers of overlapping cutouts. Every ray-query backend calls this for each
// candidate hit (closest hit and shadow rays alike).
#pragma once

#include "rng.h"
#include "surface.h"
#include "texture_eval.h"

namespace tessera {

// time: the ray's (a moving triangle's texture point is where it is then);
// instance: the candidate's (TraceHit::instance), whose texture point is in
// render space like any other.
TESSERA_HOST_DEVICE inline bool alpha_ignores_hit(const SceneView& s, uint32_t tri, int32_t instance, Float b1, Float b2,
                                                  const Vec3& o, const Vec3& d, Float time) {
  const TextureSlot& slot = s.triangle_alpha[tri];
  Float a = slot.value.x;
  if (slot.texture >= 0) {
    TraceHit at;
    at.t = 0.f;
    at.triangle = tri;
    at.b1 = b1;
    at.b2 = b2;
    at.instance = instance;
    a = eval_slot(s, slot, texture_point(make_surface_hit(s, at, time))).x;
  }
  if (a >= 1.f) return false;
  if (!(a > 0.f)) return true;
  const uint64_t h = mix_bits(hash_vec3(o) ^ (hash_vec3(d) * 0xd1b54a32d192ed03ull) ^
                              (static_cast<uint64_t>(tri) * 0x9e3779b97f4a7c15ull));
  const Float u = static_cast<Float>(h >> 40) * 0x1p-24f;
  return u >= a;
}

}  // namespace tessera
