// The medium-interaction stage (pbrt-v4's volpath for homogeneous and grid
// media): the segment just traced runs through the path's medium, which
// attenuates it or, sampling a collision (medium.h), scatters the path at a
// point inside: direct light there, then a direction from the phase function.
#pragma once

#include "integrator/integrator_direct.h"
#include "integrator/integrator_scatter.h"

namespace tessera {

enum class MediumStep {
  kPass,       // the segment reaches the surface (or escapes), attenuated
  kScattered,  // the path scattered in the medium and goes on from there
  kEnd,        // the path ends
};

// A scattering event at distance t along the ray in medium m.
template <class Ctx>
TESSERA_HOST_DEVICE TESSERA_INLINE MediumStep scatter_in_medium(Ctx& x, PathState& st, const Medium& m, Float t) {
  if (m.subsurface) {
    if (++st.walk_events > kMaxSubsurfaceEvents) return MediumStep::kEnd;
  } else if (st.depth++ == x.settings.max_depth) {
    return MediumStep::kEnd;
  }
  ++x.c.medium_vertices;
  x.guide.at_medium_vertex();
  if (st.depth == 1) st.first_vertex_connectable = x.settings.light_traced_caustics;
  st.last_vertex_delta_only = false;
  const PhaseScatter at{st.ray.o + t * st.ray.d, -st.ray.d, m.g, st.medium};
  const Float u_select = x.rng.uniform();
  const Vec2 u_light = x.rng.uniform2();
  const Vec2 u_phase = x.rng.uniform2();
  Float direct = 0.f;  // unweighted NEE estimate of light scattered here (guide targets)
  if (x.settings.nee && x.s.num_lights > 0 && !m.subsurface)
    direct = sample_direct(x, st, at, -1, 0.f, u_select, u_light).estimate;
  if (x.learn) learning_at_medium_vertex(x.guide, direct, st.segment_tr, x.c.guide_updates);
  // Henyey-Greenstein sampling is exact: the weight p / pdf is 1.
  Float phase_pdf = 0.f;
  const Vec3 wi = sample_henyey_greenstein(at.wo, m.g, u_phase, &phase_pdf);
  if (!(phase_pdf > 0.f)) return MediumStep::kEnd;
  st.mis.pdf = phase_pdf;
  st.mis.balance = false;
  st.mis.pending = false;
  st.mis.cell = -1;
  st.mis.p = at.p;
  st.mis.n = Vec3(0.f);
  st.mis.in_medium = true;
  st.specular_bounce = false;
  st.ray.o = at.p;
  st.ray.d = wi;
  return survives_roulette(x, st, -1, 0) ? MediumStep::kScattered : MediumStep::kEnd;
}

// The segment [0, t_max) of the ray through the path's medium.
template <class Ctx>
TESSERA_HOST_DEVICE TESSERA_INLINE MediumStep medium_interaction(Ctx& x, PathState& st, Float t_max) {
  const Medium m = medium_at(x.s, st.medium, st.wl);
  if (medium_absorbs_only(m)) {
    // Its transmittance: no collision to sample, no path ended by absorption.
    const Rgb T = medium_transmittance(x.s, m, st.ray.o, st.ray.d, t_max, st.wl);
    st.beta *= T;
    st.rr_beta *= T;
    st.segment_tr = luminance(T);
  } else {
    const Float u_channel = x.rng.uniform();
    const Float u_dist = x.rng.uniform();
    const MediumSegment seg = sample_medium(x.s, m, st.ray.o, st.ray.d, t_max, u_channel, u_dist, st.wl, st.heroes);
    if (st.depth < x.settings.max_depth) st.L += st.beta * seg.emitted;
    st.beta *= seg.weight;
    st.rr_beta *= seg.weight;
    st.segment_tr = luminance(seg.weight);
    if (seg.scattered) {
      if (is_black(st.beta)) return MediumStep::kEnd;
      return scatter_in_medium(x, st, m, seg.t);
    }
  }
  return is_black(st.beta) ? MediumStep::kEnd : MediumStep::kPass;
}

}  // namespace tessera
