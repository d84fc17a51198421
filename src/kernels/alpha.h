// pbrt-v4's alpha cutouts: a hit on a surface whose alpha is a < 1 is ignored
// with probability 1 - a. The decision is a hash of the ray and the triangle,
// as pbrt-v4 hashes the ray: deterministic per ray, independent between the
// layers of overlapping cutouts. Every ray-query backend calls this for each
// candidate hit (closest hit and shadow rays alike).
#pragma once

#include "rng.h"
#include "texture_eval.h"

namespace tessera {

TESSERA_HOST_DEVICE inline bool alpha_ignores_hit(const SceneView& s, uint32_t tri, Float b1, Float b2, const Vec3& o,
                                                  const Vec3& d) {
  const TextureSlot& slot = s.triangle_alpha[tri];
  Float a = slot.value.x;
  if (slot.texture >= 0) {
    const uint32_t* idx = s.indices + 3 * static_cast<size_t>(tri);
    const Float b0 = 1.f - b1 - b2;
    const Vec2 uv = (s.triangles[tri].flags & kTriHasUv) ? b0 * s.uvs[idx[0]] + b1 * s.uvs[idx[1]] + b2 * s.uvs[idx[2]]
                                                         : Vec2(b1 + b2, b2);
    a = eval_slot(s, slot, uv).x;
  }
  if (a >= 1.f) return false;
  if (!(a > 0.f)) return true;
  auto bits = [](Float f) {
    union { Float f; uint32_t u; } c;
    c.f = f;
    return static_cast<uint64_t>(c.u);
  };
  uint64_t h = mix_bits(bits(o.x) ^ (bits(o.y) << 21) ^ (bits(o.z) << 42));
  h = mix_bits(h ^ bits(d.x) ^ (bits(d.y) << 21) ^ (bits(d.z) << 42));
  h = mix_bits(h ^ (static_cast<uint64_t>(tri) * 0x9e3779b97f4a7c15ull));
  const Float u = static_cast<Float>(h >> 40) * 0x1p-24f;
  return u >= a;
}

}  // namespace tessera
