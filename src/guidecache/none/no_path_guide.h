// The per-path guide of an unguided render (guidecache/path_guide.h).
#pragma once

#include "guidecache/path_guide.h"

namespace tessera {

// No guiding: every hook is the unguided integrator's choice (light
// selection by the scene's light sampler, next-event estimation everywhere,
// the BSDF alone).
struct NoPathGuide {
  PendingTarget pending;  // never filled
  TESSERA_HOST_DEVICE Float nee_probability(int32_t) const { return 1.f; }
  TESSERA_HOST_DEVICE Float light_pmf(const SceneView& s, const LightQuery& q, int32_t, uint32_t li) const {
    return light_choice_pmf(s, q, li);
  }
  TESSERA_HOST_DEVICE uint32_t pick_light(const SceneView& s, const LightQuery& q, int32_t, Float u, Float* pmf) const {
    return choose_light(s, q, u, pmf);
  }
  TESSERA_HOST_DEVICE bool locates(int32_t, int32_t) const { return false; }
  TESSERA_HOST_DEVICE int32_t locate(const Vec3&, const Vec3&) { return -1; }
  TESSERA_HOST_DEVICE bool reused_site() const { return false; }
  TESSERA_HOST_DEVICE void at_medium_vertex() {}
  TESSERA_HOST_DEVICE void note_normal(int32_t, const Vec3&) const {}
  TESSERA_HOST_DEVICE bool learned(int32_t) const { return false; }
  TESSERA_HOST_DEVICE Float probability(int32_t, const BsdfParams&, bool) const { return 0.f; }
  TESSERA_HOST_DEVICE void prefetch_sample(int32_t, Float) const {}
  using DirLookup = Float;
  TESSERA_HOST_DEVICE DirLookup lookup(int32_t, const Vec3&) const { return 0.f; }
  TESSERA_HOST_DEVICE Float lookup_pdf(DirLookup) const { return 0.f; }
  TESSERA_HOST_DEVICE bool sample(int32_t, Float, Vec2, Vec3*, Float*, uint32_t*) const { return false; }
  TESSERA_HOST_DEVICE uint32_t bin_of(const Vec3&) const { return 0; }
  TESSERA_HOST_DEVICE Float bin_pdf(int32_t, uint32_t) const { return 0.f; }
  TESSERA_HOST_DEVICE Float value(int32_t, uint32_t) const { return 0.f; }
  TESSERA_HOST_DEVICE Float survival(int32_t, uint32_t, Float, Float, Float) const { return 0.f; }
  template <class ToLocal>
  TESSERA_HOST_DEVICE Float bins_integral(int32_t, const BsdfParams&, bool, const Vec3&, const ToLocal&, PixelSampler&,
                                          GuideBootstrap*) const {
    return 0.f;
  }
  TESSERA_HOST_DEVICE bool record(int32_t, uint32_t, Float, const GuideBootstrap&) const { return false; }
  TESSERA_HOST_DEVICE void record_light(int32_t, uint32_t, Float) const {}
  TESSERA_HOST_DEVICE void record_nee(int32_t, Float, Float) const {}
  TESSERA_HOST_DEVICE bool learns_mix(int32_t, Float) const { return false; }
  TESSERA_HOST_DEVICE void record_mix(int32_t, const GuideMixSample&, Float) const {}
};

}  // namespace tessera
