// What the integrator needs from the guide cache beyond guidecache/table/guide_view.h:
// mixture light selection (power-based + learned, with the true mixture pmf)
// and the learning targets of Dahm & Keller's update rule.
#pragma once

#include "kernels/bsdf.h"
#include "kernels/light_choice.h"
#include "guidecache/table/guide_view.h"
#include "kernels/rng.h"
#include "kernels/sampler.h"
#include "kernels/scene_view.h"

namespace tessera {

// Probability that a vertex in `cell` traces next-event estimation at all
// (GuideView::nee_prob; 1 without a guide).
TESSERA_HOST_DEVICE inline Float nee_probability(const GuideView* g, int32_t cell) {
  return g && cell >= 0 ? g->nee_prob[cell] : 1.f;
}

// Learned light selection, shared by both guides: with probability lp a
// light is drawn from the learned distribution, else by the scene's light
// sampler (light_choice.h). Its pmf for a light of sampler pmf p_base and
// learned pmf p_learned:
TESSERA_HOST_DEVICE inline Float mixed_light_pmf(Float lp, Float p_base, Float p_learned) {
  return (1.f - lp) * p_base + lp * p_learned;
}
// ... and the draw with one uniform number u (lp > 0): the part of u below lp,
// rescaled, picks from the learned distribution (sample_learned(u')).
template <class SampleLearned>
TESSERA_HOST_DEVICE inline uint32_t pick_mixed_light(const SceneView& s, const LightQuery& q, Float lp, Float u,
                                                     const SampleLearned& sample_learned) {
  if (u < lp) return sample_learned(glm::min(u / lp, 0x1.fffffep-1f));
  Float pmf_base = 0.f;
  return choose_light(s, q, glm::min((u - lp) / (1.f - lp), 0x1.fffffep-1f), &pmf_base);
}

// Probability that next-event estimation at point q in `cell` samples light
// li: that it is traced at all, times the selection probability (cell < 0 or
// no learned lights: the light sampler's alone). The density of the
// light-sampling strategy in every MIS weight carries it.
TESSERA_HOST_DEVICE inline Float light_select_pmf(const SceneView& s, const LightQuery& q, const GuideView* g,
                                                  int32_t cell, uint32_t li) {
  const Float p_base = light_choice_pmf(s, q, li);
  if (!g || cell < 0) return p_base;
  const Float p_nee = g->nee_prob[cell];
  if (g->lights == 0) return p_nee * p_base;
  const Float lp = g->cell_light_prob[cell];
  return p_nee * mixed_light_pmf(lp, p_base, g->light_distribution(cell).discrete_pmf(li));
}

// Selects a light with one uniform number, given that next-event estimation
// is traced; *pmf is light_select_pmf (the traced probability included).
TESSERA_HOST_DEVICE inline uint32_t select_light(const SceneView& s, const LightQuery& q, const GuideView* g,
                                                 int32_t cell, Float u, Float* pmf) {
  const Float lp = g && g->lights > 0 && cell >= 0 ? g->cell_light_prob[cell] : 0.f;
  if (lp <= 0.f) {
    const uint32_t li = choose_light(s, q, u, pmf);
    *pmf *= nee_probability(g, cell);
    return li;
  }
  const uint32_t li = pick_mixed_light(
      s, q, lp, u, [&](Float ul) { return g->light_distribution(cell).sample_discrete(ul, nullptr); });
  *pmf = light_select_pmf(s, q, g, cell, li);
  return li;
}

// How often a vertex draws its direction from the guide. The guide samples
// Q x cos, the product with a diffuse lobe: right for diffuse and rough
// surfaces, wasteful for narrow glossy lobes, which BSDF sampling already
// follows closely (taking half their samples away made the glossy scene
// worse). The share fades from the full mixture weight at roughness alpha
// >= 0.3 to nothing at alpha <= 0.05.
// Dielectrics are not guided: the field weights bins by max(cos, 0) about the
// surface it was learned on, so guided samples would almost never go through
// (measured: ~3x the variance behind a rough glass slab). Nor is hair, which
// scatters over the whole sphere about its fibre, nor the lobe a
// subsurface walk leaves by (its side is the one the guide never learned).
// The fading by BSDF of a full weight p (both guides).
TESSERA_HOST_DEVICE inline Float guide_probability_for_bsdf(Float p, const BsdfParams& b, bool lambertian_only) {
  if (lambertian_only || b.type == BsdfType::Diffuse) return p;
  if (b.type == BsdfType::Dielectric || b.type == BsdfType::Hair || b.type == BsdfType::SubsurfaceExit) return 0.f;
  Float alpha = glm::sqrt(b.alpha_x * b.alpha_y);
  if (b.type == BsdfType::CoatedDiffuse) alpha = glm::max(alpha, 0.3f);  // a rough coat over a diffuse base
  return p * glm::clamp((alpha - 0.05f) / 0.25f, 0.f, 1.f);
}
TESSERA_HOST_DEVICE inline Float guide_probability(const GuideView& g, int32_t cell, const BsdfParams& b,
                                                   bool lambertian_only) {
  return guide_probability_for_bsdf(g.cell_guide_prob(cell), b, lambertian_only);
}

// What a guided vertex remembers of its sampled direction until the learning
// target of that direction arrives (one vertex later).
struct GuideMixSample {
  Float fcos = 0.f;       // luminance of f |cos| of the direction taken
  Float guide_pdf = 0.f;  // density of the guide's strategy for it
  Float bsdf_pdf = 0.f;   // density of the BSDF's strategy for it
  Float mix_pdf = 0.f;    // the mixture density it was drawn with
  // Emission met along it that the integrator weighs by MIS against NEE
  // (left out of the learning target, which is NEE's to deliver): its
  // luminance and the light-sampling density of the direction. Its weight
  // depends on the mixture density, so every candidate sees it with its own.
  Float emitted = 0.f;
  Float light_pdf = 0.f;
  // The vertex's own next-event sample, whose MIS weight also depends on the
  // mixture density: luminance of f |cos| tr L, its light density, and the
  // guide's and the BSDF's densities of its direction (nee_value 0: none).
  Float nee_value = 0.f;
  Float nee_light_pdf = 0.f;
  Float nee_guide_pdf = 0.f;
  Float nee_bsdf_pdf = 0.f;
};

// One candidate's second moment (below) for a vertex's mixture sample m
// with learning target T, radiance in units of `scale`, had it sampled with
// weight a: the direction's (3.4e38 where a gives it no density) plus its
// next-event sample's. Both guides' mixture statistics (guide_record_mix,
// neural_record_mix).
TESSERA_HOST_DEVICE inline Float guide_mix_moment(const GuideMixSample& m, Float target, Float scale, Float a) {
  const Float pk = a * m.guide_pdf + (1.f - a) * m.bsdf_pdf;
  const Float radiance = m.emitted > 0.f ? target + m.emitted * power_heuristic(pk, m.light_pdf) : target;
  const Float v = (m.fcos / scale) * radiance;
  Float moment = pk > 0.f ? v * v / (pk * m.mix_pdf) : 3.4e38f;
  if (m.nee_value > 0.f && m.nee_light_pdf > 0.f) {
    const Float pk_light_dir = a * m.nee_guide_pdf + (1.f - a) * m.nee_bsdf_pdf;
    const Float nee = m.nee_value * power_heuristic(m.nee_light_pdf, pk_light_dir) / (m.nee_light_pdf * scale);
    moment += nee * nee;
  }
  return moment;
}

// Records, for every candidate weight a_k, the second moment the vertex's
// estimator would have had with a_k, estimated from this vertex's two samples
// (s is the cell's scale, see below):
// - the direction, drawn with the current weight: (f cos L_k / s)^2 /
//   (p_k p_cur), with L_k the radiance it brings: the learning target T plus
//   the MIS-weighted emission it met, weighted as it would be with p_k;
// - the next-event sample, drawn independently of a_k:
//   (f cos tr Le w_k / (p_light s))^2, its MIS weight w_k taken against p_k.
// Scored on T alone, a cell lit directly by a large emitter (an environment)
// saw only the indirect light the guide finds, chose high guide weights, and
// took from the direct light the BSDF samples that its MIS with NEE needs
// (material-testball's floor: 7x the variance of no guiding).
// A sample too large for the fixed point is counted in rejected[2], for all
// candidates alike. Out of line on the GPU (learning only).
TESSERA_HOST_DEVICE TESSERA_DEVICE_NOINLINE inline void guide_record_mix(const GuideView& g, int32_t cell,
                                                                         const GuideMixSample& m, Float target) {
  // The cell's scale: the radiance it reflects, learned indirect plus NEE's
  // direct share, so that cells lit mostly directly stay in range too.
  const Float direct = g.value[static_cast<size_t>(cell) * g.stride + g.nee_entry];
  const Float scale = g.irradiance[cell] * kInvPi + glm::max(direct, 0.f);
  if (!(scale > 0.f) || !(m.mix_pdf > 0.f) || !(target >= 0.f)) return;
  Float s[kGuideMixEntries];
  Float largest = 0.f;
  for (uint32_t k = 0; k < kGuideMixEntries; ++k) {
    s[k] = guide_mix_moment(m, target, scale, guide_mix_candidate(k));
    largest = glm::max(largest, s[k]);
  }
  if (!(largest <= g.max_target)) {
    guide_acc_add(g, &g.rejected[2], 1);
    return;
  }
  for (uint32_t k = 0; k < kGuideMixEntries; ++k) guide_record(g, cell, g.mix_entry + k, s[k]);
}

// Guide-driven Russian roulette, after Vorba & Krivanek 2016 ("Adjoint-driven
// Russian roulette and splitting"): the probability with which the guide
// would let a path continue along a direction in `bin` from a vertex in
// `cell`, given its throughput luminance after scattering and the radiance
// the guide predicted for the whole path (`path_expected`, at its first
// vertex): a continuation expected to bring at least 1/kGuidedRouletteWindow
// of that always survives, others in proportion. The integrator takes the
// larger of this and pbrt-v4's throughput rule, so the guide only ever keeps
// paths alive: throughput roulette, blind to where light is, kills as many
// paths heading for the light as away from it (in a room lit through a door
// gap it left 97 % of the paths without a contribution), while a field that
// has learned nothing, or something wrong, can never make roulette harsher
// than it was. Unbiased for any survival probability, as the caller divides
// by it. The window (PathSettings::guided_roulette_window) trades time per
// sample for error: on door-ajar at equal time, window 2 (the default) beat 1
// and 4; 0.5 and 0.25 give shorter paths and higher error. Letting the guide
// also kill paths (down to a floor of 0.2) was no better, and with a floor of
// 0.05 paths the field had not learned about yet came back 20-fold as fireflies.
constexpr Float kGuidedRouletteWindow = 2.f;

// The most a path's guided sampling may raise its weight against BSDF
// sampling before the rest of the path samples its BSDF alone (integrator.h,
// guide_ratio).
constexpr Float kMaxGuideRatio = 8.f;
TESSERA_HOST_DEVICE inline Float guided_survival(const GuideView& g, int32_t cell, uint32_t bin, Float throughput,
                                                 Float path_expected, Float window) {
  const Float expected = throughput * guide_value(g, cell, bin);
  return glm::min(window * expected / path_expected, 1.f);
}

// The part of a learning target that looks beyond vertex y: an estimate of
// the integral over incident directions of Q(y, wi) f(wo, wi) |cos| from y's
// bins (expected SARSA), or of max Q(y) times the BSDF's albedo (Q-learning).
//  - Lambertian y: closed forms over the cell, rho/pi * irradiance or rho * qmax.
//  - Other non-delta BSDFs: one bin j drawn from y's guide distribution,
//    Q_j f(w_j) |cos_j| dOmega / p_j, an unbiased estimate of the bin sum.
// Delta BSDFs are handled by the caller with the direction actually sampled.
// The BSDF is given in its local frame; w_j is taken to it by `to_local`.
// wo_local by value: its address goes to the out-of-line BSDF code.
template <class ToLocal>
TESSERA_HOST_DEVICE inline Float guide_bins_integral(const GuideView& g, int32_t cell, const BsdfParams& b, bool lambertian,
                                                     Vec3 wo_local, const ToLocal& to_local, PixelSampler& rng) {
  if (lambertian) {
    Float rho = luminance(b.reflectance);
    return g.target == GuideTarget::QLearning ? rho * g.qmax[cell] : rho * kInvPi * g.irradiance[cell];
  }
  Float pmf = 0.f;
  uint32_t j = g.sample_bin(cell, rng.uniform(), &pmf);
  if (!(pmf > 0.f)) return 0.f;
  Vec3 wi = to_local(g.bin_dirs[j]);
  Float fc = luminance(bsdf_eval(b, wo_local, wi)) * fabsf(wi.z) * g.bin_solid_angle() / pmf;
  Float q = g.target == GuideTarget::QLearning ? g.qmax[cell] : guide_value(g, cell, j);
  return q * fc;
}

}  // namespace tessera
