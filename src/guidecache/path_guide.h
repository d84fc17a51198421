// The integrator's one interface to a guide, per path: locate a vertex,
// the mixture weight there, sample a direction and its density, the
// radiance predicted along a bin, and record learning targets. Three plain
// implementations, picked at compile time by the specialisation bits
// (make_path_guide): NoPathGuide (no guiding: light selection by power,
// nothing else), TablePathGuide over the Q-table's GuideView, and
// NeuralPathGuide, which runs the network once per vertex into one of two
// sites (the current vertex and the one whose target is pending). A vertex
// is named by an int32_t handle: the table's cell, the neural site's slot;
// -1 is none. Each also carries the path's pending learning target
// (PendingTarget, path_learning.h), which the integrator's hooks fill and
// commit.
//
// The hooks, by the stage that calls them (integrator.h):
// - surface interaction: locates(depth), locate, reused_site, note_normal;
// - medium interaction: at_medium_vertex;
// - direct light: nee_probability, pick_light, light_pmf, lookup, lookup_pdf;
// - the vertex's estimate: learned, bins_integral, record, record_nee,
//   record_light;
// - scattering: probability, prefetch_sample, sample, bin_of, bin_pdf,
//   value, learns_mix, record_mix;
// - Russian roulette: survival.
//
// This file: what every guide shares; each guide lives in its own folder
// (none/, table/, neural/) and path_guides.h is the one place naming them.
#pragma once

#include "kernels/bsdf.h"
#include "kernels/sampler.h"
#include "kernels/scene_view.h"
#include "guidecache/table/guiding.h"

namespace tessera {

// The bootstrapped part of a learning target: coef x the guide's value at
// vertex `slot` (of bin `bin`, or kNeuralIrradiance: the irradiance), as it
// was then (`value`). The network recomputes it as it trains
// (NeuralTrainingSample); the table ignores it. slot -1: none.
struct GuideBootstrap {
  int32_t slot = -1;
  uint32_t bin = 0;
  Float coef = 0.f;
  Float value = 0.f;
};

// Learning update waiting for the end of the current segment x -> y: into
// entry `bin` of x's vertex `cell`. `le` is the part of the target known at
// y's hit (emission next-event estimation does not cover); the rest comes
// from y's NEE and bins, or, where y has only a delta lobe (at_delta), from
// the direction it takes.
struct PendingTarget {
  int32_t cell = -1;
  uint32_t bin = 0;
  Float le = 0.f;
  bool at_delta = false;
  // The pending direction's densities, for the mixture-weight statistics
  // (mix.mix_pdf 0: the vertex did not take part).
  GuideMixSample mix;
};

}  // namespace tessera
