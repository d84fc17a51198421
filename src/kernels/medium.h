// Homogeneous participating media (pbrt-v4's HomogeneousMedium and
// MediumInterface) with the Henyey-Greenstein phase function: the pieces the
// volumetric path tracer needs per ray segment.
//
// Distances are sampled from the mixture of the three channels' exponential
// densities (pick a channel uniformly, sample its free path) and weighted by
// the mixture's density: that is pbrt-v4's hero-wavelength MIS carried over to
// RGB, unbiased in every channel, including chromatic media where one channel
// has no extinction at all.
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
};

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

// What happened on a ray segment of length t_max through a medium.
struct MediumSegment {
  bool scattered = false;  // a real collision at distance t (else the ray reached t_max)
  Float t = 0.f;
  Rgb weight{1.f};    // factor for the path throughput: T * sigma_s / pdf, or T / P(reach t_max)
  Rgb emitted{0.f};   // medium emission estimate over the segment, to add times the throughput before `weight`
  Rgb transmittance{1.f};  // T(t) itself (for learning targets)
};

// One collision-distance sample; u_channel picks the channel, u_dist its free path.
TESSERA_HOST_DEVICE inline MediumSegment sample_medium_segment(const Medium& m, Float t_max, Float u_channel,
                                                               Float u_dist) {
  MediumSegment seg;
  const Rgb sigma_t = medium_sigma_t(m);
  const int c = glm::min(static_cast<int>(u_channel * 3.f), 2);
  const Float t = sigma_t[c] > 0.f ? -glm::log(1.f - u_dist) / sigma_t[c] : kInfinity;
  if (t < t_max) {
    const Rgb T = transmittance(sigma_t, t);
    const Float pdf = (sigma_t.x * T.x + sigma_t.y * T.y + sigma_t.z * T.z) / 3.f;
    seg.scattered = true;
    seg.t = t;
    seg.transmittance = T;
    if (!(pdf > 0.f)) {
      seg.weight = Rgb(0.f);
      return seg;
    }
    seg.weight = T * m.sigma_s / pdf;
    seg.emitted = T * m.sigma_a * m.Le / pdf;
    return seg;
  }
  const Rgb T = transmittance(sigma_t, t_max);
  const Float p_reach = (T.x + T.y + T.z) / 3.f;
  seg.t = t_max;
  seg.transmittance = T;
  seg.weight = p_reach > 0.f ? T / p_reach : Rgb(0.f);
  return seg;
}

// Whether a medium only absorbs: its transmittance is then applied exactly
// instead of sampling collisions that would end the path.
TESSERA_HOST_DEVICE inline bool medium_absorbs_only(const Medium& m) {
  // (A grid medium's transmittance is estimated by ratio tracking.)
  return is_black(m.sigma_s) && is_black(m.Le) && !m.grid_emits;
}

}  // namespace tessera
