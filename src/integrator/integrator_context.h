// What every stage of the integrator reads and does not change during a
// path (integrator.h): the scene, the ray queries, the settings, the path's
// random numbers, its guide and its counters. A wavefront renderer would
// pass the same as each kernel's launch parameters.
#pragma once

#include "guidecache/path_guides.h"
#include "guidecache/path_learning.h"
#include "integrator/path_state.h"
#include "kernels/bsdf_spec.h"
#include "kernels/effects.h"
#include "kernels/sampler.h"

namespace tessera {

// The per-path guide for a specialisation: none, the Q-table or the network.
template <uint32_t Spec>
TESSERA_HOST_DEVICE inline auto make_path_guide(const PathSettings& settings) {
  return make_path_guide<Spec>(settings.guide, settings.neural, settings.neural_first);
}

template <uint32_t Spec, class Tracer, class PG>
struct PathContext {
  static constexpr uint32_t kSpec = Spec;
  using Guide = PG;
  static constexpr bool kGuide = (Spec & kSpecGuiding) != 0;
  static constexpr bool kMedia = (Spec & kSpecMedia) != 0;
  static constexpr bool kNonDiffuse = (Spec & kSpecNonDiffuse) != 0;
  const SceneView& s;
  const Tracer& tracer;
  const PathSettings& settings;
  PixelSampler& rng;
  PG& guide;
  PathCounters& c;
  bool learn;           // this path's targets train the guide
  bool guide_roulette;  // guide-driven roulette (see survives_roulette)
};

}  // namespace tessera
