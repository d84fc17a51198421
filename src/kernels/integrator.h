// Unidirectional path tracing with next-event estimation and MIS (power
// heuristic), Russian roulette, pbrt-v4's depth counting. Templated on the
// scene's specialisation bits (effects.h) and on the ray-query backend, which
// provides (time: Ray::time, for moving shapes):
//   bool intersect(const Vec3& o, const Vec3& d, Float tmax, TraceHit* hit, Float time) const;
//   bool occluded(const Vec3& o, const Vec3& d, Float tmax, Float time) const;   // d unit length
#pragma once

#include "bsdf.h"
#include "camera.h"
#include "effects.h"
#include "guiding.h"
#include "path_guide.h"
#include "light_sampling.h"
#include "material_eval.h"
#include "rng.h"
#include "bump.h"
#include "sampler.h"
#include "volume_transport.h"

namespace tessera {

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
  // many times over (see guide_ratio in trace_path).
  Float max_guide_ratio = kMaxGuideRatio;
  // The light tracer (light_paths.h) delivers the emission of paths whose
  // first vertex scatters non-specularly and whose later vertices are all
  // delta-only surfaces: the path tracer leaves it out.
  bool light_traced_caustics = false;
  // With kSpecNeural: the pixel's first-vertex site the tile loop keeps
  // between its samples (null: none; path_guide.h).
  NeuralFirstSite* neural_first = nullptr;
};

namespace detail {

// Lambertian fast path used when the scene has no other BSDF.
TESSERA_HOST_DEVICE inline Rgb diffuse_eval(const BsdfParams& b, const Vec3& wo, const Vec3& wi) {
  return same_hemisphere(wo, wi) ? b.reflectance * kInvPi : Rgb(0.f);
}

}  // namespace detail

template <uint32_t Spec>
TESSERA_HOST_DEVICE inline Rgb eval_f(const BsdfParams& b, const Vec3& wo, const Vec3& wi) {
  if constexpr ((Spec & kSpecNonDiffuse) != 0) return bsdf_eval(b, wo, wi);
  else return detail::diffuse_eval(b, wo, wi);
}
// For light samples (next-event estimation): see bsdf_eval_light.
template <uint32_t Spec>
TESSERA_HOST_DEVICE inline Rgb eval_f_light(const BsdfParams& b, const Vec3& wo, const Vec3& wi) {
  if constexpr ((Spec & kSpecNonDiffuse) != 0) return bsdf_eval_light(b, wo, wi);
  else return detail::diffuse_eval(b, wo, wi);
}
template <uint32_t Spec>
TESSERA_HOST_DEVICE inline Float eval_pdf(const BsdfParams& b, const Vec3& wo, const Vec3& wi) {
  if constexpr ((Spec & kSpecNonDiffuse) != 0) return bsdf_pdf(b, wo, wi);
  else return same_hemisphere(wo, wi) ? abs_cos_theta(wi) * kInvPi : 0.f;
}
// The density MIS weighs the BSDF's strategy by (bsdf_mis_pdf), and whether
// the balance heuristic applies (the coated BSDFs under volpath).
template <uint32_t Spec>
TESSERA_HOST_DEVICE inline Float eval_mis_pdf(const BsdfParams& b, const Vec3& wo, const Vec3& wi, Float pdf) {
  if constexpr ((Spec & kSpecNonDiffuse) != 0) return bsdf_mis_estimated(b) ? bsdf_mis_pdf(b, wo, wi) : pdf;
  else return pdf;
}
template <uint32_t Spec>
TESSERA_HOST_DEVICE inline bool mis_balance(const SceneView& s, const BsdfParams& b) {
  if constexpr ((Spec & kSpecNonDiffuse) != 0) return s.layered_mis_balance && bsdf_mis_estimated(b);
  else return false;
}
template <uint32_t Spec>
TESSERA_HOST_DEVICE inline bool sample_f(const BsdfParams& b, const Vec3& wo, Float uc, Vec2 u, BsdfSample* bs) {
  if constexpr ((Spec & kSpecNonDiffuse) != 0) {
    return bsdf_sample(b, wo, uc, u, bs);
  } else {
    (void)uc;
    Vec3 wi = sample_cosine_hemisphere(u);
    if (wo.z < 0.f) wi.z = -wi.z;
    if (wi.z == 0.f) return false;
    bs->wi = wi;
    bs->pdf = abs_cos_theta(wi) * kInvPi;
    bs->f = b.reflectance * kInvPi;
    bs->lobe = kLobeReflection | kLobeDiffuse;
    bs->eta = 1.f;
    return bs->pdf > 0.f;
  }
}

// The shading frame at a hit: the material's bump or normal map applied to
// h.ns first (kSpecTextures). Anisotropic BSDFs need pbrt's orientation (x
// along dp/du); any frame around the normal serves the isotropic ones.
template <uint32_t Spec>
TESSERA_HOST_DEVICE inline Frame shading_frame(const SceneView& s, const BsdfParams& bsdf, SurfaceHit& h) {
  if constexpr ((Spec & kSpecTextures) != 0) {
    if (bsdf.bump >= 0) h.ns = bumped_shading_normal(s, bsdf.bump, h);
    else if (bsdf.normal_map >= 0) h.ns = normal_mapped_shading_normal(s, bsdf.normal_map, h);
  }
  // Hair: x along the fibre (a curve's u).
  return (Spec & kSpecNonDiffuse) && (bsdf.alpha_x != bsdf.alpha_y || bsdf.type == BsdfType::Hair)
             ? Frame::from_tangent(h.ns, surface_dpdu(s, h.triangle))
             : Frame::from_z(h.ns);
}

template <uint32_t Spec>
TESSERA_HOST_DEVICE inline uint32_t lobes_of(const BsdfParams& b) {
  return (Spec & kSpecNonDiffuse) ? bsdf_lobes(b) : (kLobeReflection | kLobeDiffuse);
}

// Radiance arriving along the ray; consumes random numbers from rng in a fixed order.
//
// With kSpecMedia the path also scatters in participating media (pbrt-v4's
// volpath for homogeneous media): the ray starts in the camera's medium,
// changes medium where it crosses a surface that is a medium transition, and
// each segment through a medium samples a collision (medium.h). Shadow rays
// accumulate transmittance through "interface" surfaces (volume_transport.h).
//
// With kSpecGuiding, directions at vertices without a delta lobe are drawn
// from a mixture of the BSDF and the learned guide (probability
// guide.cell_guide_prob(cell)), weighted by the mixture pdf, which also
// stands in for the BSDF pdf in every MIS weight: the estimator stays unbiased
// whatever the guide has learned. (Weighing MIS by the BSDF pdf alone, which
// saves NEE a guide lookup, measured 5 % worse on shelter at equal samples
// and no faster.) Each traced segment x -> y sends Dahm & Keller's target
// Le(y) + (integral of Q f cos at y) to x's cell, and each shadow ray sends
// its unoccluded contribution to the light-selection entry of x's cell.
//
// With next-event estimation the field learns the radiance NEE does not
// deliver: emission that NEE samples is left out of the targets and the light
// reflected at y directly is added from y's own (unweighted) NEE estimate.
// Guided directions then go where indirect light comes from instead of
// duplicating the light samples; Q stays the full reflected radiance, so
// light that reaches x over several bounces is still learned.
template <uint32_t Spec, class Tracer>
TESSERA_HOST_DEVICE Rgb trace_path(const SceneView& s, const Tracer& tracer, Ray ray, PixelSampler& rng,
                                   const PathSettings& settings, PathCounters& c, Wavelengths* wl = nullptr) {
  constexpr bool kGuide = (Spec & kSpecGuiding) != 0;
  constexpr bool kNeural = kGuide && (Spec & kSpecNeural) != 0;
  constexpr bool kMedia = (Spec & kSpecMedia) != 0;
  int32_t medium = kMedia ? s.camera_medium : -1;  // the medium the ray travels in (-1: vacuum)
  HeroChannels heroes;  // the channel media sample distances with, and the MIS over it (medium.h)
  // Luminance of the medium's weight on the segment just traced (its
  // transmittance, or the collision estimator's weight): learning targets
  // are the radiance arriving at x, after the medium between.
  Float segment_tr = 1.f;
  const bool learn = kGuide && settings.learn;
  // The guide, per vertex (path_guide.h); `guide` is the table's view where
  // it learns next-event probability (the network does not: null).
  auto pg = [&]() {
    if constexpr (kNeural) return NeuralPathGuide(settings.neural, settings.neural_first);
    else return TablePathGuide{settings.guide};
  }();
  const GuideView* guide = kGuide ? pg.light_guide() : nullptr;
  // Light selection at a vertex (its guide handle; -1: none): the guide's,
  // learned where it learns one, else by power.
  auto light_pmf_at = [&](int32_t cell, uint32_t li) -> Float {
    if constexpr (kGuide) return pg.light_pmf(s, cell, li);
    else return light_select_pmf(s, nullptr, cell, li);
  };
  auto pick_light_at = [&](int32_t cell, Float u, Float* pmf) -> uint32_t {
    if constexpr (kGuide) return pg.pick_light(s, cell, u, pmf);
    else return select_light(s, nullptr, cell, u, pmf);
  };
  Rgb L(0.f), beta(1.f);
  // Russian roulette decides on the throughput BSDF sampling alone would have
  // (pbrt-v4's rule). Guided directions carry small weights exactly where the
  // guide is confident; letting those weights drive roulette would kill the
  // paths guiding worked to find. Any survival probability keeps the
  // estimator unbiased, as the weight is divided by it.
  Rgb rr_beta(1.f);
  // Guide-driven roulette compares each continuation with the radiance the
  // guide predicted for the whole path at its first vertex where it predicted
  // any (0: not yet; roulette then follows the throughput alone). Learning
  // paths use it too: a target needs only the segment x -> y and y's own
  // estimate, so the roulette changes how often a bin is updated, never what
  // it learns.
  const bool guide_roulette = kGuide && settings.guided_roulette;
  Float path_expected = 0.f;
  int32_t depth = 0;
  bool specular_bounce = false;
  // Light-traced caustics (PathSettings::light_traced_caustics): the light
  // tracer takes a path that ends on an emitter if its first vertex scattered
  // non-specularly (it connects there) and the vertex before the emitter has
  // only delta lobes (its walk starts with such a chain).
  bool first_vertex_connectable = false;
  bool last_vertex_delta_only = false;
  // What MIS weighs the last sampled direction by: its pdf (the mixture's
  // when guided), with the coated BSDFs' estimate in place of theirs
  // (eval_mis_pdf), and with which heuristic.
  Float prev_mis_pdf = 0.f;
  bool prev_mis_balance = false;
  // A coated BSDF's estimate costs a short layered walk: it is taken only
  // when the direction finds a light (mis_pdf_of_last_direction), from the
  // vertex's BSDF, directions and guide mixture kept here.
  struct PendingMisPdf {
    BsdfParams bsdf;
    Vec3 wo, wi;
    Float guide_p = 0.f, guide_density = 0.f;
    bool pending = false;
  } prev_mis;
  auto mis_pdf_of_last_direction = [&]() {
    if constexpr ((Spec & kSpecNonDiffuse) != 0) {
      if (prev_mis.pending) {
        const Float mis_bsdf = bsdf_mis_pdf(prev_mis.bsdf, prev_mis.wo, prev_mis.wi);
        prev_mis_pdf = prev_mis.guide_p * prev_mis.guide_density + (1.f - prev_mis.guide_p) * mis_bsdf;
        prev_mis.pending = false;
      }
    }
    return prev_mis_pdf;
  };
  // How much guiding has scaled the path's weight against BSDF sampling:
  // the product over guided vertices of bsdf_pdf / mixture_pdf. Each factor
  // is 1 on average, but over hundreds of guided vertices their product is
  // lognormal-like (docs/guiding.md, an albedo-1 enclosure at depth 1000):
  // unbiased, too heavy-tailed to trust. A path whose ratio has passed
  // settings.max_guide_ratio samples its BSDF alone from then on, a choice
  // made from its past only, so the estimate stays unbiased and the ratio
  // stays bounded (by that times one vertex's factor).
  Float guide_ratio = 1.f;
  Vec3 prev_p(0.f);  // last scattering point: MIS on emitter hits measures from it, as NEE does
  bool prev_in_medium = false;  // whether it was in a medium (sample_light's in_medium)
  int32_t prev_cell = -1;  // guide cell of the last scattering point (its light selection)
  Float eta_scale = 1.f;
  int32_t interface_skips = 0;
  int32_t walk_events = 0;  // scattering events inside subsurface media (they do not count as bounces)
  // Learning update waiting for the end of the current segment x -> y: into
  // entry pend_bin of cell pend_cell. pend_le is the part of the target known
  // at y's hit (emission NEE does not cover); the rest comes from y's NEE and
  // bins, or, at a delta vertex, from the direction it takes.
  int32_t pend_cell = -1;
  uint32_t pend_bin = 0;
  Float pend_le = 0.f;
  bool pend_at_delta = false;
  // The pending direction's densities, for the mixture-weight statistics
  // (mix_pdf 0: the vertex did not take part).
  GuideMixSample pend_mix;
  // Sends the pending target (and its mixture statistics) to x's cell.
  // MIS-weighted emission met by the pending direction, for its mixture
  // statistics (several environments: their luminances add, and the density
  // is their luminance-weighted mean).
  auto note_mis_emission = [&](Float le, Float light_pdf) {
    if (pend_cell < 0 || !(pend_mix.mix_pdf > 0.f) || !(le > 0.f)) return;
    const Float total = pend_mix.emitted + le;
    pend_mix.light_pdf = (pend_mix.light_pdf * pend_mix.emitted + light_pdf * le) / total;
    pend_mix.emitted = total;
  };
  // boot: the target's bootstrapped part (the network refreshes it as it trains).
  auto finish_target = [&](Float target, GuideBootstrap boot) {
    target *= segment_tr;
    boot.coef *= segment_tr;
    if (pg.record(pend_cell, pend_bin, target, boot)) {
      ++c.guide_updates;
      if (pend_mix.mix_pdf > 0.f) {
        pend_mix.emitted *= segment_tr;
        pg.record_mix(pend_cell, pend_mix, target);
      }
    }
  };

  for (;;) {
    TraceHit hit;
    ++c.rays;
    segment_tr = 1.f;
    const bool found = tracer.intersect(ray.o, ray.d, kInfinity, &hit, ray.time);
    if constexpr (kMedia) {
      if (medium >= 0) {
        const Medium m = medium_at(s, medium, wl);
        const Float t_max = found ? hit.t : kInfinity;
        if (medium_absorbs_only(m)) {
          // Its transmittance: no collision to sample, no path ended by absorption.
          const Rgb T = medium_transmittance(s, m, ray.o, ray.d, t_max, wl);
          beta *= T;
          rr_beta *= T;
          segment_tr = luminance(T);
        } else {
          const Float u_channel = rng.uniform();
          const Float u_dist = rng.uniform();
          const MediumSegment seg = sample_medium(s, m, ray.o, ray.d, t_max, u_channel, u_dist, wl, heroes);
          if (depth < settings.max_depth) L += beta * seg.emitted;
          beta *= seg.weight;
          rr_beta *= seg.weight;
          segment_tr = luminance(seg.weight);
          if (seg.scattered) {
            if (is_black(beta)) break;
            if (m.subsurface) {
              if (++walk_events > kMaxSubsurfaceEvents) break;
            } else if (depth++ == settings.max_depth) {
              break;
            }
            ++c.medium_vertices;
            // A pixel's first network site stands only for first vertices its
            // camera ray reached: a path that scattered first took other random
            // numbers along, which a sample reaching a surface directly samples with.
            if constexpr (kNeural) pg.at_first = false;
            if (depth == 1) first_vertex_connectable = settings.light_traced_caustics;
            last_vertex_delta_only = false;
            const Vec3 p = ray.o + seg.t * ray.d;
            const Vec3 wo = -ray.d;
            const Float u_select = rng.uniform();
            const Vec2 u_light = rng.uniform2();
            const Vec2 u_phase = rng.uniform2();
            Float direct_estimate = 0.f;  // unweighted NEE estimate of light scattered here (guide targets)
            if (settings.nee && s.num_lights > 0 && !m.subsurface) {
              Float pmf = 0.f;
              const uint32_t li = pick_light_at(-1, u_select, &pmf);
              LightSample ls;
              if (pmf > 0.f && sample_light(s, li, p, u_light, &ls, true)) {
                ls.L = light_emission(s, wl, s.lights[li], ls.L);
                const Float phase = henyey_greenstein(glm::dot(wo, ls.wi), m.g);
                const Float tmax = ls.infinite ? kInfinity : glm::length(ls.p_light - p) * 0.9999f;
                const Rgb tr = light_visibility<true>(s, tracer, p, ls.wi, tmax, medium, ray.time, c, wl);
                const Float light_pdf = pmf * ls.pdf;
                if (!is_black(tr) && light_pdf > 0.f) {
                  const Float w = ls.delta ? 1.f : power_heuristic(light_pdf, phase);
                  L += beta * tr * ls.L * (phase * w / light_pdf);
                  direct_estimate = luminance(tr * ls.L) * phase / light_pdf;
                }
              }
            }
            // The guide has no cells in media: a pending target ends here with
            // the light scattered here directly (multiple scattering is not learned).
            if (learn && pend_cell >= 0) {
              finish_target(direct_estimate, GuideBootstrap{});
              pend_cell = -1;
            }
            // Henyey-Greenstein sampling is exact: the weight p / pdf is 1.
            Float phase_pdf = 0.f;
            const Vec3 wi = sample_henyey_greenstein(wo, m.g, u_phase, &phase_pdf);
            if (!(phase_pdf > 0.f)) break;
            prev_mis_pdf = phase_pdf;
            prev_mis_balance = false;
            prev_mis.pending = false;
            prev_cell = -1;
            prev_p = p;
            prev_in_medium = true;
            specular_bounce = false;
            ray.o = p;
            ray.d = wi;
            if (depth > 1) {
              const Float survive = glm::min(1.f, max_component(rr_beta * eta_scale));
              if (survive < 1.f) {
                if (rng.uniform() < 1.f - survive) break;
                beta /= survive;
                rr_beta /= survive;
              }
            }
            continue;
          }
        }
        if (is_black(beta)) break;
      }
    }
    if (!found) {
      Rgb Le_total(0.f);
      if constexpr ((Spec & kSpecEnvironment) != 0) {
        for (uint32_t k = 0; k < s.num_infinite_lights; ++k) {
          uint32_t li = static_cast<uint32_t>(s.infinite_lights[k]);
          // A portal's sky is seen through its rectangle from the last scattering point (prev_p, where NEE
          // sampled it; the camera's position for camera rays): not from an interface the ray crossed since.
          const Vec3 from = depth == 0 ? ray.o : prev_p;
          const Rgb Le = light_emission(s, wl, s.lights[li], environment_radiance(s, s.lights[li], from, ray.d));
          Le_total += Le;
          if (depth == 0 || specular_bounce || !settings.nee) {
            L += beta * Le;
          } else {
            Float light_pdf = light_pmf_at(prev_cell, li) * environment_pdf(s, li, from, ray.d);
            L += beta * Le * mis_weight(mis_pdf_of_last_direction(), light_pdf, prev_mis_balance);
            if constexpr (kGuide) note_mis_emission(luminance(Le), light_pdf);
          }
        }
      }
      if constexpr (kGuide) {
        const bool counted = specular_bounce || !settings.nee;  // else NEE delivers the environment
        if (pend_cell >= 0) finish_target(counted ? luminance(Le_total) : 0.f, GuideBootstrap{});
      }
      break;
    }
    ++c.vertices;
    const RayPoint from_ray{ray.o, ray.d, hit.t};
    SurfaceHit h = make_surface_hit(s, hit.triangle, hit.b1, hit.b2, ray.time, &from_ray);
    Vec3 wo = -ray.d;
    const TriangleInfo& info = s.triangles[hit.triangle];

    Rgb Le_hit(0.f);  // radiance emitted at this vertex towards the previous one
    if constexpr ((Spec & kSpecAreaLights) != 0) {
      if (info.light >= 0) {
        const Light& l = s.lights[info.light];
        Float cos_l = glm::dot(h.ng, wo);
        if ((l.two_sided || cos_l > 0.f) && first_vertex_connectable && last_vertex_delta_only) {
          ++c.caustic_emission_skipped;
        } else if (l.two_sided || cos_l > 0.f) {
          Le_hit = light_emission(s, wl, l, area_light_radiance(s, l, h.uv));
          if (depth == 0 || specular_bounce || !settings.nee) {
            L += beta * Le_hit;
          } else {
            Float light_pdf = light_pmf_at(prev_cell, static_cast<uint32_t>(info.light)) *
                              area_light_pdf_from(s, l, prev_p, h.p, cos_l, prev_in_medium);
            L += beta * Le_hit * mis_weight(mis_pdf_of_last_direction(), light_pdf, prev_mis_balance);
            if constexpr (kGuide) note_mis_emission(luminance(Le_hit), light_pdf);
          }
        }
      }
    }

    BsdfParams bsdf;
    const int32_t single_before = wl ? wl->single : -1;
    if (!resolve_bsdf<Spec>(s, info.material, h, wo, &bsdf, wl)) {
      // Interface: continue through without counting a bounce (pbrt's SkipIntersection).
      ++c.interface_skips;
      if (++interface_skips > 256) break;
      if constexpr (kMedia) medium = medium_after(s, hit.triangle, h.ng, ray.d, medium);
      ray.o = offset_ray_origin(h, ray.d);
      continue;
    }
    if (wl && wl->single != single_before) {
      // The path's first dispersive surface: from here on it carries one
      // wavelength, for all three (spectral.h).
      const Rgb mask = dispersion_mask(wl->single);
      beta *= mask;
      rr_beta *= mask;
      if constexpr (kMedia) keep_only_channel(heroes, wl->single);
    }

    const Frame frame = shading_frame<Spec>(s, bsdf, h);
    Vec3 wo_l = frame.to_local(wo);
    const uint32_t lobes = lobes_of<Spec>(bsdf);
    const bool delta_lobe = (lobes & kLobeSpecular) != 0;

    int32_t cell = -1;
    // The network is not run where the path ends (it would guide nothing,
    // and the pending target is dropped there); the table still notes the normal.
    if constexpr (kGuide) {
      if (!(kNeural && depth == settings.max_depth)) {
        // The side the path is on: the two faces of a wall never share a cell.
        Vec3 n_side = glm::dot(h.ng, wo) >= 0.f ? h.ng : -h.ng;
        cell = pg.locate(h.p, n_side);
        if constexpr (kNeural) c.neural_sites_reused += pg.reused ? 1u : 0u;
        if (learn) {
          pg.note_normal(cell, n_side);
          // Emission the integrator weights by MIS is NEE's to deliver.
          pend_le = (specular_bounce || !settings.nee) ? luminance(Le_hit) : 0.f;
          pend_at_delta = delta_lobe;
        }
      }
    }

    // A path ending here leaves its last target unfinished (no NEE at y): dropped.
    if (depth++ == settings.max_depth) break;
    if (wo_l.z == 0.f) break;
    // Probability of drawing this vertex's direction from the guide (0: BSDF only).
    // Not once guiding has raised the path's weight max_guide_ratio-fold (see guide_ratio).
    Float guide_p = kGuide && !delta_lobe ? pg.probability(cell, bsdf, (Spec & kSpecNonDiffuse) == 0) : 0.f;
    if (guide_p > 0.f && !(guide_ratio <= settings.max_guide_ratio)) {
      guide_p = 0.f;
      ++c.guide_withheld_vertices;
    }
    const bool guided_vertex = guide_p > 0.f;

    // The direction's random numbers are drawn before next-event estimation so
    // that the guide's alias entry can be fetched while the shadow ray is traced.
    const Float uc = rng.uniform();
    const Vec2 u = rng.uniform2();
    if (guided_vertex) pg.prefetch_sample(cell, uc);

    // Next-event estimation at non-specular vertices (pbrt-v4's SampleLd).
    Float direct_estimate = 0.f;  // its unweighted estimate of light reflected here (guide targets)
    GuideMixSample nee_mix;  // the NEE sample's share of the mixture statistics (guided vertices)
    const bool nee_vertex = settings.nee && lobes_have_non_specular(lobes) && s.num_lights > 0;
    if (nee_vertex) {
      Float u_select = rng.uniform();
      Vec2 u_light = rng.uniform2();
      // Where the guide has learned that shadow rays bring little, the vertex
      // traces one with probability p_nee (the same number decides, rescaled).
      bool traced = true;
      if constexpr (kGuide) {
        const Float p_nee = nee_probability(guide, cell);
        if (p_nee < 1.f) {
          traced = u_select < p_nee;
          u_select = glm::min(u_select / p_nee, 0x1.fffffep-1f);
        }
      }
      Float pmf = 0.f;
      uint32_t li = 0;
      if (traced) li = pick_light_at(cell, u_select, &pmf);
      else ++c.nee_skipped;
      LightSample ls;
      Float learned = 0.f;  // unoccluded contribution of the selected light, for the guide
      if (pmf > 0.f && sample_light(s, li, h.p, u_light, &ls)) {
        ls.L = light_emission(s, wl, s.lights[li], ls.L);
        Vec3 wi_l = frame.to_local(ls.wi);
        Rgb f = eval_f_light<Spec>(bsdf, wo_l, wi_l) * abs_cos_theta(wi_l);
        if (!is_black(f)) {
          Vec3 o = offset_ray_origin(h, ls.wi);
          Float tmax = kInfinity;
          if (!ls.infinite) tmax = glm::length(ls.p_light - o) * 0.9999f;
          Float light_pdf = pmf * ls.pdf;
          // The guide's density of the light direction, for the MIS weight: its
          // memory is fetched while the shadow ray is traced.
          typename decltype(pg)::DirLookup light_dir{};
          const bool guided_light_dir = guided_vertex && !ls.delta;
          if (guided_light_dir) light_dir = pg.lookup(cell, ls.wi);
          const Rgb tr = light_pdf > 0.f ? light_visibility<kMedia>(s, tracer, o, ls.wi, tmax,
                                                                    kMedia ? medium_after(s, hit.triangle, h.ng, ls.wi, medium) : -1,
                                                                    ray.time, c, wl)
                                         : Rgb(0.f);
          if (!is_black(tr)) {
            Float w = 1.f;
            if (!ls.delta) {
              const Float scatter_pdf = eval_pdf<Spec>(bsdf, wo_l, wi_l);
              Float mis_pdf = eval_mis_pdf<Spec>(bsdf, wo_l, wi_l, scatter_pdf);
              if (guided_light_dir) {
                const Float guide_pdf_l = pg.lookup_pdf(light_dir);
                if (learn) {
                  nee_mix.nee_value = luminance(f * tr * ls.L);
                  nee_mix.nee_light_pdf = light_pdf;
                  nee_mix.nee_guide_pdf = guide_pdf_l;
                  nee_mix.nee_bsdf_pdf = scatter_pdf;
                }
                mis_pdf = guide_p * guide_pdf_l + (1.f - guide_p) * mis_pdf;
              }
              w = mis_weight(light_pdf, mis_pdf, mis_balance<Spec>(s, bsdf));
            }
            L += beta * f * tr * ls.L * (w / light_pdf);
            learned = luminance(f * tr * ls.L) / ls.pdf;
          }
        }
      }
      if (learn && pmf > 0.f) pg.record_light(cell, li, learned);
      direct_estimate = pmf > 0.f ? learned / pmf : 0.f;
    }
    // Radiance the guide expects y to reflect towards x: NEE's unweighted
    // estimate plus the learned integral. It completes the pending target, and
    // gives guide-driven roulette the path's expected radiance.
    const bool completes_target = learn && pend_cell >= 0 && !pend_at_delta;
    const bool sets_expectation = guide_roulette && !(path_expected > 0.f) && !delta_lobe && pg.learned(cell);
    const bool records_nee = learn && nee_vertex;
    if (completes_target || sets_expectation || records_nee) {
      const bool lambertian = (Spec & kSpecNonDiffuse) == 0 || bsdf.type == BsdfType::Diffuse;
      GuideBootstrap boot;
      const Float indirect = pg.bins_integral(cell, bsdf, lambertian, wo_l,
                                              [&](const Vec3& v) { return frame.to_local(v); }, rng, &boot);
      const Float reflected = direct_estimate + indirect;
      if (records_nee) {
        // The two shares of the light reflected here, for nee_prob.
        pg.record_nee(cell, direct_estimate, indirect);
      }
      if (completes_target) {
        finish_target(pend_le + reflected, boot);
        pend_cell = -1;
      }
      if (sets_expectation) path_expected = luminance(beta) * reflected;
    }

    BsdfSample bs;
    Vec3 wi;  // world space
    Float scatter_pdf;
    Float bsdf_pdf;  // the BSDF's own pdf of the direction taken (for roulette)
    uint32_t wi_bin = 0;  // guide bin of wi (guiding only)
    Float guide_density = 0.f;  // the guide's density for wi (guided vertices only)
    if (guided_vertex) {
      // One extra dimension picks the strategy; the mixture pdf weights either.
      ++c.guidable_vertices;
      const Float p = guide_p;
      if (rng.uniform() < p) {
        ++c.guided_samples;
        if (!pg.sample(cell, uc, u, &wi, &guide_density, &wi_bin)) break;
        bs.wi = frame.to_local(wi);
        bs.f = eval_f<Spec>(bsdf, wo_l, bs.wi);
        const bool transmit = !same_hemisphere(wo_l, bs.wi);
        bs.lobe = transmit ? kLobeTransmission : kLobeReflection;
        bs.eta = transmit ? (wo_l.z > 0.f ? bsdf.ior : 1.f / bsdf.ior) : 1.f;
        bsdf_pdf = eval_pdf<Spec>(bsdf, wo_l, bs.wi);
        scatter_pdf = p * guide_density + (1.f - p) * bsdf_pdf;
      } else {
        if (!sample_f<Spec>(bsdf, wo_l, uc, u, &bs) || !(bs.pdf > 0.f)) break;
        wi = frame.to_world(bs.wi);
        bsdf_pdf = bs.pdf;
        wi_bin = pg.bin_of(wi);
        guide_density = pg.bin_pdf(cell, wi_bin);
        scatter_pdf = p * guide_density + (1.f - p) * bs.pdf;
      }
    } else {
      if (!sample_f<Spec>(bsdf, wo_l, uc, u, &bs) || !(bs.pdf > 0.f)) break;
      wi = frame.to_world(bs.wi);
      scatter_pdf = bsdf_pdf = bs.pdf;
      if (learn || (path_expected > 0.f && pg.learned(cell))) wi_bin = pg.bin_of(wi);
    }
    if (!(scatter_pdf > 0.f)) break;
    const Rgb weight = bs.f * (abs_cos_theta(bs.wi) / scatter_pdf);
    if (learn) {
      // A delta vertex's integral is the direction it actually took.
      if (pend_at_delta && pend_cell >= 0) {
        const Float value = pg.value(cell, wi_bin);
        finish_target(pend_le + value * luminance(weight), GuideBootstrap{cell, wi_bin, luminance(weight), value});
      }
      pend_cell = cell;
      pend_bin = wi_bin;
      pend_at_delta = false;
      // Only vertices that sample with the cell's own weight (not faded by a
      // glossy lobe) inform it.
      pend_mix = nee_mix;
      if (guided_vertex && pg.learns_mix(cell, guide_p)) {
        pend_mix.fcos = luminance(bs.f) * abs_cos_theta(bs.wi);
        pend_mix.bsdf_pdf = bsdf_pdf;
        pend_mix.guide_pdf = guide_density;
        pend_mix.mix_pdf = scatter_pdf;
      }
    }
    beta *= weight;
    rr_beta *= bsdf_pdf > 0.f ? bs.f * (abs_cos_theta(bs.wi) / bsdf_pdf) : weight;
    if (guided_vertex) guide_ratio *= bsdf_pdf / scatter_pdf;
    prev_mis_balance = mis_balance<Spec>(s, bsdf);
    prev_mis_pdf = scatter_pdf;
    prev_mis.pending = false;
    if constexpr ((Spec & kSpecNonDiffuse) != 0) {
      if (bsdf_mis_estimated(bsdf) && !(bs.lobe & kLobeSpecular)) {  // a specular direction is not weighed
        prev_mis.bsdf = bsdf;
        prev_mis.wo = wo_l;
        prev_mis.wi = bs.wi;
        prev_mis.guide_p = guided_vertex ? guide_p : 0.f;
        prev_mis.guide_density = guide_density;
        prev_mis.pending = true;
      }
    }
    prev_cell = cell;
    specular_bounce = (bs.lobe & kLobeSpecular) != 0;
    if (depth == 1) first_vertex_connectable = settings.light_traced_caustics && !specular_bounce;
    last_vertex_delta_only = !lobes_have_non_specular(lobes);
    if (bs.lobe & kLobeTransmission) eta_scale *= sqr(bs.eta);
    if (keeps_lobe_side(bsdf, bs.lobe)) wi = keep_on_lobe_side(wi, wo, h.ng, (bs.lobe & kLobeTransmission) != 0);
    ray.o = offset_ray_origin(h, wi);
    ray.d = wi;
    prev_p = h.p;
    prev_in_medium = false;
    if constexpr (kMedia) medium = medium_after(s, hit.triangle, h.ng, wi, medium);

    // Russian roulette after the second bounce: pbrt-v4's rule, on throughput
    // corrected for radiance scaling at refractive boundaries; where the guide
    // has learned and predicted this path's radiance, a path it expects to
    // bring light survives more often.
    if (depth > 1) {
      Float survive = glm::min(1.f, max_component(rr_beta * eta_scale));
      if (kGuide && path_expected > 0.f && pg.learned(cell)) {
        survive = glm::max(survive, pg.survival(cell, wi_bin, luminance(beta), path_expected,
                                                settings.guided_roulette_window));
        ++c.guided_roulette;
      }
      if (survive < 1.f) {
        if (rng.uniform() < 1.f - survive) break;
        beta /= survive;
        rr_beta /= survive;
      }
    }
    if (is_black(beta)) break;
  }
  return L;
}

}  // namespace tessera
