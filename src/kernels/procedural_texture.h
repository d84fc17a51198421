// pbrt-v4's procedural textures, evaluated at a point: polka dots, marble,
// windy waves (fbm and wrinkled are perlin_noise.h's fbm and turbulence).
#pragma once

#include "perlin_noise.h"

namespace tessera {

// pbrt-v4's InsidePolkaDot: a dot of radius 0.35 in about half of the unit
// cells centred on integer st, shifted by up to 0.15 within its cell.
TESSERA_HOST_DEVICE inline bool inside_polka_dot(Vec2 st) {
  constexpr Float kLimit = 16777216.f;  // beyond, st has no fraction left: no dots
  if (!(glm::abs(st.x) < kLimit && glm::abs(st.y) < kLimit)) return false;
  const Float s_cell = glm::floor(st.x + 0.5f), t_cell = glm::floor(st.y + 0.5f);
  if (!(perlin_noise(Vec3(s_cell + 0.5f, t_cell + 0.5f, 0.5f)) > 0.f)) return false;
  constexpr Float kRadius = 0.35f, kMaxShift = 0.5f - kRadius;
  const Float s_center = s_cell + kMaxShift * perlin_noise(Vec3(s_cell + 1.5f, t_cell + 2.8f, 0.5f));
  const Float t_center = t_cell + kMaxShift * perlin_noise(Vec3(s_cell + 4.5f, t_cell + 9.8f, 0.5f));
  const Vec2 d = st - Vec2(s_center, t_center);
  return glm::dot(d, d) < kRadius * kRadius;
}

// pbrt-v4's WindyTexture: wave height scaled by a slowly varying wind strength.
TESSERA_HOST_DEVICE inline Float windy_value(const Vec3& p) {
  const Float wind_strength = fbm_noise(0.1f * p, 0.5f, 3);
  const Float wave_height = fbm_noise(p, 0.5f, 6);
  return glm::abs(wind_strength) * wave_height;
}

// pbrt-v4's MarbleTexture: bands along y, perturbed by fbm, coloured by a
// cubic Bezier spline through pbrt-v4's nine greys and blues (p already
// scaled by the texture's "scale").
TESSERA_HOST_DEVICE inline Rgb marble_value(const Vec3& p, Float variation, Float omega, int32_t octaves) {
  const Float marble = p.y + variation * fbm_noise(p, omega, octaves);
  Float t = 0.5f + 0.5f * glm::sin(marble);
  if (!(t >= 0.f && t <= 1.f)) t = 0.f;  // NaN from a non-finite point
  const Rgb colors[9] = {Rgb(.58f, .58f, .6f), Rgb(.58f, .58f, .6f), Rgb(.58f, .58f, .6f),
                         Rgb(.5f, .5f, .5f),   Rgb(.6f, .59f, .58f),  Rgb(.58f, .58f, .6f),
                         Rgb(.58f, .58f, .6f), Rgb(.2f, .2f, .33f),   Rgb(.58f, .58f, .6f)};
  constexpr int32_t kSegments = 9 - 3;
  const int32_t first = glm::min(static_cast<int32_t>(glm::floor(t * kSegments)), kSegments - 1);
  t = t * kSegments - static_cast<Float>(first);
  // De Casteljau, as pbrt-v4's EvaluateCubicBezier.
  const Rgb* cp = colors + first;
  auto lerp = [](Float u, const Rgb& a, const Rgb& b) { return (1.f - u) * a + u * b; };
  const Rgb c01 = lerp(t, cp[0], cp[1]), c12 = lerp(t, cp[1], cp[2]), c23 = lerp(t, cp[2], cp[3]);
  return 1.5f * lerp(t, lerp(t, c01, c12), lerp(t, c12, c23));
}

}  // namespace tessera
