// What a path carries from one stage of the integrator to the next
// (integrator.h): its settings (the same for every path of a tile), its
// counters (summed over a tile) and its state (PathState). A wavefront
// renderer would keep one PathState per path in memory between its kernels;
// the CPU keeps it on the stack.
#pragma once

#include "guidecache/neural/neural_view.h"
#include "guidecache/table/guiding.h"
#include "kernels/camera.h"
#include "kernels/medium.h"
#include "kernels/spectral.h"

namespace tessera {

struct NeuralFirstSite;

// Per-path counters; summed over a tile with integer adds (order-independent).
struct PathCounters {
  uint64_t rays = 0;          // closest-hit queries
  uint64_t shadow_rays = 0;   // occlusion queries
  uint64_t vertices = 0;      // surface interactions along paths
  uint64_t interface_skips = 0;
  uint64_t guidable_vertices = 0;  // vertices where the guide could be used (no delta lobe)
  uint64_t guided_samples = 0;     // directions drawn from the guide
  uint64_t guide_withheld_vertices = 0;  // guidable vertices left to the BSDF: the path's guide ratio was too high
  uint64_t guide_updates = 0;      // direction targets accepted by the guide
  uint64_t guided_roulette = 0;    // roulette decisions the guide's prediction took part in
  uint64_t nee_skipped = 0;        // vertices that skipped next-event estimation (GuideView::nee_prob)
  uint64_t medium_vertices = 0;    // scattering events in participating media
  uint64_t light_paths = 0;        // light paths traced for caustics (light_paths.h)
  uint64_t light_splats = 0;       // pixel contributions they made
  uint64_t caustic_emission_skipped = 0;  // emitter hits left to the light tracer
  uint64_t neural_sites_reused = 0;       // vertices that reused their pixel's first site (NeuralFirstSite)
  uint64_t untraceable_rays = 0;          // rays the tracer refused (kernels/ray_guard.h): misses or occluded
};

struct PathSettings {
  int32_t max_depth = 5;
  bool nee = true;  // false: emitters are found by BSDF sampling only (for tests and comparisons)
  GuideView guide;  // read and updated by the kSpecGuiding specialisation only
  NeuralGuideView neural;  // instead of guide with kSpecNeural
  // Whether this path's targets train the guide (kSpecGuiding only). A path
  // that does not learn still samples from the guide; it skips the learning
  // work, which costs as much as guided sampling itself.
  bool learn = true;
  // Guide-driven Russian roulette (kSpecGuiding only; see guided_survival).
  // Off: pbrt-v4's throughput rule everywhere.
  bool guided_roulette = true;
  // A continuation the guide expects to bring at least 1/window of the path's
  // predicted radiance always survives (see guided_survival): smaller windows
  // give shorter paths, less time per sample and more noise per sample.
  Float guided_roulette_window = kGuidedRouletteWindow;
  // A path samples its BSDF alone once guiding has raised its weight this
  // many times over (see PathState::guide_ratio).
  Float max_guide_ratio = kMaxGuideRatio;
  // The light tracer (light_paths.h) delivers the emission of paths whose
  // first vertex scatters non-specularly and whose later vertices are all
  // delta-only surfaces: the path tracer leaves it out.
  bool light_traced_caustics = false;
  // With kSpecNeural: the pixel's first-vertex site the tile loop keeps
  // between its samples (null: none; path_guide.h).
  NeuralFirstSite* neural_first = nullptr;
};

// What multiple importance sampling remembers of the last scattering vertex
// for an emitter the next segment finds (integrator_emission.h).
struct MisMemory {
  // The density MIS weighs the sampled direction by (the mixture's where
  // guided), with the coated BSDFs' estimate in place of theirs
  // (eval_mis_pdf), and the heuristic.
  Float pdf = 0.f;
  bool balance = false;
  // A coated BSDF's estimate costs a short layered walk: it is taken only
  // when the direction finds a light (mis_pdf), from the vertex's BSDF,
  // directions and guide mixture kept here.
  BsdfParams bsdf;
  Vec3 wo, wi;
  Float guide_p = 0.f, guide_density = 0.f;
  bool pending = false;
  Vec3 p{0.f};             // the vertex: MIS on emitter hits measures from it, as NEE does
  Vec3 n{0.f};             // its shading normal (zero in a medium): the light sampler's choice depends on it
  bool in_medium = false;  // whether it was in a medium (sample_light's in_medium)
  int32_t cell = -1;       // its guide handle (its light selection)
};

struct PathState {
  Ray ray;
  Rgb L{0.f};
  Rgb beta{1.f};
  // Russian roulette decides on the throughput BSDF sampling alone would have
  // (pbrt-v4's rule). Guided directions carry small weights exactly where the
  // guide is confident; letting those weights drive roulette would kill the
  // paths guiding worked to find. Any survival probability keeps the
  // estimator unbiased, as the weight is divided by it.
  Rgb rr_beta{1.f};
  Float eta_scale = 1.f;
  int32_t depth = 0;
  int32_t medium = -1;  // the medium the ray travels in (-1: vacuum)
  HeroChannels heroes;  // the channel media sample distances with, and the MIS over it (medium.h)
  // Luminance of the medium's weight on the segment just traced (its
  // transmittance, or the collision estimator's weight): learning targets
  // are the radiance arriving at x, after the medium between.
  Float segment_tr = 1.f;
  bool specular_bounce = false;
  MisMemory mis;
  // Guide-driven roulette compares each continuation with the radiance the
  // guide predicted for the whole path at its first vertex where it predicted
  // any (0: not yet; roulette then follows the throughput alone).
  Float path_expected = 0.f;
  // How much guiding has scaled the path's weight against BSDF sampling:
  // the product over guided vertices of bsdf_pdf / mixture_pdf. Each factor
  // is 1 on average, but over hundreds of guided vertices their product is
  // lognormal-like (docs/guiding.md, an albedo-1 enclosure at depth 1000):
  // unbiased, too heavy-tailed to trust. A path whose ratio has passed
  // settings.max_guide_ratio samples its BSDF alone from then on, a choice
  // made from its past only, so the estimate stays unbiased and the ratio
  // stays bounded (by that times one vertex's factor).
  Float guide_ratio = 1.f;
  // Light-traced caustics (PathSettings::light_traced_caustics): the light
  // tracer takes a path that ends on an emitter if its first vertex scattered
  // non-specularly (it connects there) and the vertex before the emitter has
  // only delta lobes (its walk starts with such a chain).
  bool first_vertex_connectable = false;
  bool last_vertex_delta_only = false;
  int32_t interface_skips = 0;
  int32_t walk_events = 0;  // scattering events inside subsurface media (they do not count as bounces)
  Wavelengths* wl = nullptr;  // spectral transport's wavelengths (null: RGB)
};

}  // namespace tessera
