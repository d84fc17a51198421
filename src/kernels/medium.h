// Homogeneous participating media (pbrt-v4's HomogeneousMedium and
// MediumInterface) with the Henyey-Greenstein phase function: the pieces the
// volumetric path tracer needs per ray segment.
//
// Distances (and, in grids, collision events) are sampled with one channel's
// coefficients, the path's hero channel, picked uniformly once per path, and
// weighted by the balance heuristic over the three channels as heroes of the
// whole path: pbrt-v4's hero-wavelength MIS (its r_u), carried over to RGB.
// Unbiased in every channel, including chromatic media where one channel has
// no extinction at all, and with weights bounded by the number of channels
// however many collisions a path has (a per-collision mixture multiplies
// ratios along the path: heavy tails in deep chromatic media).
#pragma once

#include "sampling.h"
#include "vecmath.h"

namespace tessera {

struct Medium {
  Rgb sigma_a{0.f}, sigma_s{0.f};  // per unit length, "scale" folded in
  Rgb Le{0.f};                     // emitted radiance (pbrt-v4: Le * Lescale, emitted where sigma_a is)
  Float g = 0.f;                   // Henyey-Greenstein asymmetry, in [-0.99, 0.99]
  int32_t grid = -1;               // >= 0: a density grid (SceneView::grids) scales sigma_a, sigma_s and Le
  int32_t grid_emits = 0;          // 1: the grid's emission (a temperature or Lescale grid) glows, whatever Le is
  // 1: the inside of a "subsurface" material. Its scattering events are one
  // random walk, which costs one bounce of maxdepth as pbrt-v4's BSSRDF does
  // (at most kMaxSubsurfaceEvents of them), and take no light samples: the
  // boundary around them blocks every one (the walk's exit takes them).
  int32_t subsurface = 0;
};

constexpr int32_t kMaxSubsurfaceEvents = 4096;

// The media on either side of a surface (-1: vacuum); inside is the side the
// geometric normal points away from. A surface with inside == outside is not a
// transition: rays keep the medium they were in (pbrt-v4's IsMediumTransition).
struct MediumInterface {
  int16_t inside = -1, outside = -1;
};

TESSERA_HOST_DEVICE inline bool is_transition(MediumInterface mi) { return mi.inside != mi.outside; }

// Medium on the side of the surface that direction w (leaving it) points into.
TESSERA_HOST_DEVICE inline int32_t medium_towards(MediumInterface mi, const Vec3& ng, const Vec3& w) {
  return glm::dot(w, ng) > 0.f ? mi.outside : mi.inside;
}

TESSERA_HOST_DEVICE inline Rgb medium_sigma_t(const Medium& m) { return m.sigma_a + m.sigma_s; }

// exp(-sigma * t) per channel; 1 where sigma is 0 (also for t = infinity).
TESSERA_HOST_DEVICE inline Rgb transmittance(const Rgb& sigma_t, Float t) {
  Rgb T;
  for (int c = 0; c < 3; ++c) T[c] = sigma_t[c] > 0.f ? glm::exp(-sigma_t[c] * t) : 1.f;
  return T;
}

// pbrt-v4's convention: wo points back along the path, so g > 0 favours
// wi = -wo (forward scattering).
TESSERA_HOST_DEVICE inline Float henyey_greenstein(Float cos_wo_wi, Float g) {
  const Float denom = 1.f + g * g + 2.f * g * cos_wo_wi;
  return kInv4Pi * (1.f - g * g) / (denom * safe_sqrt(denom));
}

// Samples wi exactly in proportion to henyey_greenstein(dot(wo, wi), g).
TESSERA_HOST_DEVICE inline Vec3 sample_henyey_greenstein(const Vec3& wo, Float g, Vec2 u, Float* pdf) {
  // Cosine between the propagation direction -wo and wi (the textbook form).
  Float cos_fwd;
  if (fabsf(g) < 1e-3f) {
    cos_fwd = 1.f - 2.f * u.x;
  } else {
    const Float s = (1.f - g * g) / (1.f - g + 2.f * g * u.x);
    cos_fwd = glm::clamp((1.f + g * g - s * s) / (2.f * g), -1.f, 1.f);
  }
  const Float sin_fwd = safe_sqrt(1.f - cos_fwd * cos_fwd);
  const Float phi = 2.f * kPi * u.y;
  const Frame f = Frame::from_z(-wo);
  const Vec3 wi = f.to_world(Vec3(sin_fwd * glm::cos(phi), sin_fwd * glm::sin(phi), cos_fwd));
  *pdf = henyey_greenstein(-cos_fwd, g);
  return wi;
}

// The path's hero channel and each channel's path pdf relative to it (up
// to a common factor: only ratios matter).
struct HeroChannels {
  int32_t hero = -1;  // -1: not chosen yet (choose_hero)
  Rgb r{1.f};
};

TESSERA_HOST_DEVICE inline void choose_hero(HeroChannels& h, Float u) {
  if (h.hero < 0) h.hero = glm::min(static_cast<int32_t>(u * 3.f), 2);
}

// An event the hero's coefficients sampled, with per-channel densities p
// (any common unit): the factor its integrand is multiplied by (the
// balance heuristic over heroes, as a ratio to the path so far), 0 if the
// hero could not have sampled it. Updates the channels' relative pdfs.
TESSERA_HOST_DEVICE inline Float hero_event(HeroChannels& h, const Rgb& p) {
  const Rgb rp = h.r * p;
  const Float mean_rp = (rp.x + rp.y + rp.z) / 3.f;
  const Float ph = p[h.hero];
  if (!(mean_rp > 0.f) || !(ph > 0.f)) return 0.f;
  const Float k = (h.r.x + h.r.y + h.r.z) / 3.f / mean_rp;
  h.r = rp / max_component(rp);  // only ratios matter: kept at most 1, finite
  return k;
}

// After a dispersive surface only channel c carries light (spectral.h): it
// becomes the hero for the rest of the path, so no distance is sampled with
// a channel whose throughput is 0. (The path's pdf is then the mixture so far
// times channel c's from here: each remaining event weighs 1 / p[c].)
TESSERA_HOST_DEVICE inline void keep_only_channel(HeroChannels& h, int32_t c) {
  h.hero = c;
  h.r = Rgb(0.f);
  h.r[c] = 1.f;
}

// What happened on a ray segment of length t_max through a medium.
struct MediumSegment {
  bool scattered = false;  // a real collision at distance t (else the ray reached t_max)
  Float t = 0.f;
  Rgb weight{1.f};    // factor for the path throughput: T * sigma_s / pdf, or T / P(reach t_max)
  Rgb emitted{0.f};   // medium emission estimate over the segment, to add times the throughput before `weight`
  Rgb transmittance{1.f};  // T(t) itself (for learning targets)
};

// One collision-distance sample with the hero's extinction (h.hero chosen);
// u_dist picks the free path.
TESSERA_HOST_DEVICE inline MediumSegment sample_medium_segment(const Medium& m, Float t_max, HeroChannels& h,
                                                               Float u_dist) {
  MediumSegment seg;
  const Rgb sigma_t = medium_sigma_t(m);
  const int c = h.hero;
  const Float t = sigma_t[c] > 0.f ? -glm::log(1.f - u_dist) / sigma_t[c] : kInfinity;
  if (t < t_max) {
    const Rgb T = transmittance(sigma_t, t);
    seg.scattered = true;
    seg.t = t;
    seg.transmittance = T;
    const Float k = hero_event(h, sigma_t * T);  // each channel's free-path density at t
    seg.weight = k * T * m.sigma_s;
    seg.emitted = k * T * m.sigma_a * m.Le;
    return seg;
  }
  const Rgb T = transmittance(sigma_t, t_max);
  seg.t = t_max;
  seg.transmittance = T;
  seg.weight = hero_event(h, T) * T;  // each channel's probability of reaching t_max
  return seg;
}

// Whether a medium only absorbs: its transmittance is then applied exactly
// instead of sampling collisions that would end the path.
TESSERA_HOST_DEVICE inline bool medium_absorbs_only(const Medium& m) {
  // (A grid medium's transmittance is estimated by ratio tracking.)
  return is_black(m.sigma_s) && is_black(m.Le) && !m.grid_emits;
}

}  // namespace tessera
