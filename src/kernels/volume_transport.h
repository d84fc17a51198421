// Shadow rays through media (the volumetric integrator's next-event
// estimation): surfaces with the "interface" material only bound media, so
// a shadow ray passes them, switching medium where they are transitions, and
// accumulates each medium's transmittance; any other surface blocks it.
#pragma once

#include "material_eval.h"
#include "medium.h"
#include "ray_guard.h"
#include "scene_view.h"
#include "surface.h"

namespace tessera {

// The medium a ray leaving triangle tri in direction w travels in: the
// surface's medium on that side where it is a transition, else `current`.
TESSERA_HOST_DEVICE inline int32_t medium_after(const SceneView& s, uint32_t tri, const Vec3& ng, const Vec3& w,
                                                int32_t current) {
  if (!s.triangle_media) return current;
  const MediumInterface mi = s.triangle_media[tri];
  return is_transition(mi) ? medium_towards(mi, ng, w) : current;
}

// Transmittance of medium m (as the path sees it: medium_at) along o + t d,
// t in [0, t_max]: exact for a homogeneous medium, a ratio-tracking estimate for a grid.
TESSERA_HOST_DEVICE inline Rgb medium_transmittance(const SceneView& s, const Medium& m, const Vec3& o, const Vec3& d,
                                                    Float t_max, const Wavelengths* wl) {
  if (m.grid >= 0) return grid_transmittance(m, s.grids[m.grid], o, d, t_max, wl);
  return transmittance(medium_sigma_t(m), t_max);
}

// One collision sample on a segment through `m` (medium.h, grid_medium.h).
// wl: the path's wavelengths under spectral transport (a grid's emission is
// evaluated at them), else null. u_channel picks the path's hero channel at
// its first medium segment (the number is drawn on every segment, so a path
// draws the same sampler dimensions either way).
TESSERA_HOST_DEVICE inline MediumSegment sample_medium(const SceneView& s, const Medium& m, const Vec3& o, const Vec3& d,
                                                       Float t_max, Float u_channel, Float u_dist,
                                                       const Wavelengths* wl, HeroChannels& h) {
  choose_hero(h, u_channel);
  if (m.grid >= 0) return sample_grid_segment(m, s.grids[m.grid], o, d, t_max, u_dist, wl, h);
  return sample_medium_segment(m, t_max, h, u_dist);
}

// Transmittance from o to o + t_max d (d unit length, t_max = kInfinity for
// infinite lights) starting in `medium` (-1: vacuum); 0 when a surface
// blocks. A mix is resolved as a camera path arriving along d would resolve
// it. Each ray query counts as a shadow ray.
template <class Tracer, class Counters>
TESSERA_HOST_DEVICE Rgb shadow_transmittance(const SceneView& s, const Tracer& tracer, Vec3 o, const Vec3& d,
                                             Float t_max, int32_t medium, Float time, Counters& c,
                                             const Wavelengths* wl) {
  if (!s.has_interfaces) {
    ++c.shadow_rays;
    if (tracer.occluded(o, d, t_max, time)) return Rgb(0.f);
    return medium >= 0 ? medium_transmittance(s, medium_at(s, medium, wl), o, d, t_max, wl) : Rgb(1.f);
  }
  Rgb tr(1.f);
  const bool infinite = !(t_max < kInfinity);
  const Vec3 target = o + t_max * d;
  // A shadow ray crossing more boundaries than this is treated as blocked.
  for (int32_t crossing = 0; crossing < 256; ++crossing) {
    TraceHit hit;
    ++c.shadow_rays;
    // A ray the tracer refuses (ray_guard.h) is blocked, as occluded() answers
    // for it (and counts it); intersect() would call it a miss: light through.
    if (!ray_traceable(o, d, t_max)) {
      (void)tracer.occluded(o, d, t_max, time);
      return Rgb(0.f);
    }
    if (!tracer.intersect(o, d, t_max, &hit, time)) {
      if (medium >= 0) tr *= medium_transmittance(s, medium_at(s, medium, wl), o, d, t_max, wl);
      return tr;
    }
    const RayPoint from_ray{o, d, hit.t};
    const SurfaceHit h = make_surface_hit(s, hit, time, &from_ray);
    if (resolve_material<kSpecAll>(s, s.triangles[hit.triangle].material, h, -d)->type != MaterialType::Interface)
      return Rgb(0.f);
    if (medium >= 0) tr *= medium_transmittance(s, medium_at(s, medium, wl), o, d, hit.t, wl);
    if (is_black(tr)) return tr;
    medium = medium_after(s, hit.triangle, h.ng, d, medium);
    o = offset_ray_origin(h, d);
    if (!infinite) {
      t_max = glm::dot(target - o, d);
      if (!(t_max > 0.f)) return tr;
    }
  }
  return Rgb(0.f);
}

// What reaches o from o + t_max d: 1 or 0 from one occlusion query, or, in
// the volumetric specialisation (media or interface surfaces), the
// transmittance through media and interfaces.
template <bool kMedia, class Tracer, class Counters>
TESSERA_HOST_DEVICE Rgb light_visibility(const SceneView& s, const Tracer& tracer, const Vec3& o, const Vec3& d,
                                         Float t_max, int32_t medium, Float time, Counters& c, const Wavelengths* wl) {
  if constexpr (kMedia) {
    return shadow_transmittance(s, tracer, o, d, t_max, medium, time, c, wl);
  } else {
    (void)s;
    (void)medium;
    (void)wl;
    ++c.shadow_rays;
    return tracer.occluded(o, d, t_max, time) ? Rgb(0.f) : Rgb(1.f);
  }
}

}  // namespace tessera
