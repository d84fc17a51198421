// The network's per-path guide (guidecache/path_guide.h): its inference
// per vertex, the pixel's first-site reuse, its mixture statistics.
#pragma once

#include "guidecache/path_guide.h"
#include "guidecache/neural/neural_view.h"

namespace tessera {

// A learning vertex's mixture statistics for the network's one weight (the
// table's per cell, guide_record_mix): the second moment of the vertex's
// estimate (its direction's and its next-event sample's) had it sampled
// with each candidate weight, in units of the network's output scale
// squared, added to the sink in fixed point (kNeuralMixMomentUnit). One
// vertex's sum over the candidates is capped at kNeuralMixVertexCap (its
// candidates keep their proportions): a few fireflies do not decide the
// scene's weight alone, and the integer sums stay far from overflow. A NaN
// or an overflow is left out and counted. Out of line on the GPU (learning only).
TESSERA_HOST_DEVICE TESSERA_DEVICE_NOINLINE inline void neural_record_mix(const NeuralGuideView& v, const GuideMixSample& m,
                                                                          Float target) {
  static_assert(kNeuralMixFirstCandidate + kNeuralMixCandidates <= kGuideMixEntries, "the table's candidates");
  NeuralSampleSink* sink = v.sink;
  if (!sink || !(m.mix_pdf > 0.f)) return;
  Float s[kNeuralMixCandidates];
  Float total = 0.f;
  for (uint32_t k = 0; k < kNeuralMixCandidates; ++k) {
    s[k] = guide_mix_moment(m, target, v.scale, guide_mix_candidate(kNeuralMixFirstCandidate + k));
    total += s[k];
  }
  if (!(total <= 3.4e38f)) {  // NaN or overflow
    ++sink->mix_rejected;
    return;
  }
  if (!(total > 0.f)) return;  // nothing to tell apart (a dark vertex)
  const Float to_units = (total > kNeuralMixVertexCap ? kNeuralMixVertexCap / total : 1.f) / kNeuralMixMomentUnit;
  for (uint32_t k = 0; k < kNeuralMixCandidates; ++k)
    sink->mix_moments[k] += static_cast<uint64_t>(s[k] * to_units + 0.5f);
  ++sink->mix_vertices;
}

// A pixel's first path vertex as the network saw it, kept from one of the
// pixel's samples to the next by the CPU tile loop (render_tile_spec): a
// later sample whose first vertex lies on the same surface nearby
// (neural_site_reusable) reuses the site instead of running the network
// again. Unbiased: the distribution a vertex samples with is then a
// function of another sample's camera ray alone (a path that scattered in
// a medium first neither reuses nor renews the site: at_medium_vertex), whose
// random numbers are other dimensions than those this vertex samples with,
// and every sampler randomises its dimensions independently; the density
// the vertex is weighted with is that distribution's. Training still
// records each vertex's own point.
struct NeuralFirstSite {
  NeuralSite site;
  bool valid = false;
};

// Whether a site computed at (site.p, site.n) may stand for a vertex at (p,
// n): the same side of a surface facing the same way, within the view's
// reuse_radius (NeuralGuideConfig::reuse_cells: by default two cells of
// the hash grid's finest level, within which about 0.7 of a pixel's later
// first vertices lay on pillars and door-ajar at 256x192, and the error
// per sample of a trained network did not change: docs/neural-guide.md).
TESSERA_HOST_DEVICE inline bool neural_site_reusable(const NeuralGuideView& v, const NeuralSite& site, const Vec3& p,
                                                     const Vec3& n) {
  const Vec3 d = p - site.p;
  return glm::dot(n, site.n) >= 0.9999f && glm::dot(d, d) <= v.reuse_radius * v.reuse_radius;
}

struct NeuralPathGuide {
  const NeuralGuideView& v;
  PendingTarget pending;
  NeuralSite site[2];
  int32_t last = 1;  // slot of the latest vertex located
  NeuralFirstSite* first = nullptr;  // the pixel's first-vertex site (null: every vertex runs the network)
  bool at_first = true;              // the next vertex located is the path's first
  bool reused = false;               // the latest vertex located reused `first`
  // The sites are filled by locate(), not zeroed here (about 1.5 kB each).
  TESSERA_HOST_DEVICE explicit NeuralPathGuide(const NeuralGuideView& view, NeuralFirstSite* first_site = nullptr)
      : v(view), first(first_site) {}
  NeuralPathGuide(const NeuralGuideView&&, NeuralFirstSite* = nullptr) = delete;  // it keeps a reference: not to a temporary
  // Next-event estimation at every vertex (no table to learn its probability).
  TESSERA_HOST_DEVICE Float nee_probability(int32_t) const { return 1.f; }
  // Light selection as the table's (light_select_pmf, select_light), from
  // the site's learned distribution where it has one, else by the scene's
  // light sampler.
  TESSERA_HOST_DEVICE Float light_pmf(const SceneView& s, const LightQuery& q, int32_t slot, uint32_t li) const {
    const Float p_base = light_choice_pmf(s, q, li);
    if (slot < 0) return p_base;
    const NeuralSite& x = site[slot];
    const Float lp = x.light_prob;
    if (!(lp > 0.f)) return p_base;
    return mixed_light_pmf(lp, p_base, li < v.lights ? x.light_pmf[li] : 0.f);
  }
  TESSERA_HOST_DEVICE uint32_t pick_light(const SceneView& s, const LightQuery& q, int32_t slot, Float u,
                                          Float* pmf) const {
    const Float lp = slot >= 0 ? site[slot].light_prob : 0.f;
    if (!(lp > 0.f)) return choose_light(s, q, u, pmf);
    const uint32_t li =
        pick_mixed_light(s, q, lp, u, [&](Float ul) { return neural_sample_light(v, site[slot], ul); });
    *pmf = light_pmf(s, q, slot, li);
    return li;
  }

  // The network is not run where the path ends (it would guide nothing,
  // and the pending target is dropped there).
  TESSERA_HOST_DEVICE bool locates(int32_t depth, int32_t max_depth) const { return depth != max_depth; }
  TESSERA_HOST_DEVICE bool reused_site() const { return reused; }
  // A pixel's first network site stands only for first vertices its camera
  // ray reached: a path that scattered in a medium first took other random
  // numbers along, which a sample reaching a surface directly samples with.
  TESSERA_HOST_DEVICE void at_medium_vertex() { at_first = false; }
  // Runs the network into the slot not holding the latest vertex: the latest
  // one (a pending target's) stays readable.
  // The path's first vertex reuses or renews the pixel's first site.
  TESSERA_HOST_DEVICE int32_t locate(const Vec3& p, const Vec3& n_side) {
    last ^= 1;
    reused = false;
    const bool keep = first != nullptr && at_first;
    at_first = false;
    if (keep && first->valid && neural_site_reusable(v, first->site, p, n_side)) {
      site[last] = first->site;
      site[last].p = p;  // what the vertex's training targets record
      site[last].n = n_side;
      reused = true;
      return last;
    }
#if TESSERA_IS_GPU_CODE
    neural_infer(v, p, n_side, &site[last]);
#else
    neural_infer_cpu(v, p, n_side, &site[last]);
#endif
    if (keep) {
      first->site = site[last];
      first->valid = true;
    }
    return last;
  }
  TESSERA_HOST_DEVICE uint32_t bins() const { return kNeuralBins; }
  TESSERA_HOST_DEVICE Vec3 bin_dir(uint32_t j) const { return v.bin_dirs[j]; }
  TESSERA_HOST_DEVICE Float irradiance(int32_t s) const { return site[s].irradiance; }
  TESSERA_HOST_DEVICE void note_normal(int32_t, const Vec3&) const {}
  TESSERA_HOST_DEVICE bool learned(int32_t s) const { return v.trained && site[s].irradiance > 0.f; }
  TESSERA_HOST_DEVICE Float probability(int32_t s, const BsdfParams& b, bool lambertian_only) const {
    return guide_probability_for_bsdf(learned(s) ? v.guide_prob : 0.f, b, lambertian_only);
  }
  TESSERA_HOST_DEVICE void prefetch_sample(int32_t, Float) const {}
  using DirLookup = Float;
  TESSERA_HOST_DEVICE DirLookup lookup(int32_t s, const Vec3& dir) const { return neural_bin_pdf(site[s], neural_bin_of(dir)); }
  TESSERA_HOST_DEVICE Float lookup_pdf(DirLookup pdf) const { return pdf; }
  TESSERA_HOST_DEVICE bool sample(int32_t s, Float u_bin, Vec2 u, Vec3* dir, Float* pdf, uint32_t* bin) {
    return neural_sample(site[s], u_bin, u, dir, pdf, bin);
  }
  TESSERA_HOST_DEVICE uint32_t bin_of(const Vec3& dir) const { return neural_bin_of(dir); }
  TESSERA_HOST_DEVICE Float bin_pdf(int32_t s, uint32_t bin) const { return neural_bin_pdf(site[s], bin); }
  TESSERA_HOST_DEVICE Float value(int32_t s, uint32_t bin) const { return neural_site_q(v, site[s], bin); }
  TESSERA_HOST_DEVICE Float survival(int32_t s, uint32_t bin, Float throughput, Float path_expected, Float window) const {
    return glm::min(window * throughput * neural_site_q(v, site[s], bin) / path_expected, 1.f);
  }
  // Expected SARSA's integral of Q f |cos| over y's bins (guide_bins_integral).
  // It is coef x one value of y's, which *boot records.
  template <class ToLocal>
  TESSERA_HOST_DEVICE Float bins_integral(int32_t s, const BsdfParams& b, bool lambertian, Vec3 wo_local,
                                          const ToLocal& to_local, PixelSampler& rng, GuideBootstrap* boot) {
    NeuralSite& y = site[s];
    *boot = GuideBootstrap{};
    if (lambertian) {
      *boot = GuideBootstrap{s, kNeuralIrradiance, luminance(b.reflectance) * kInvPi, y.irradiance};
      return boot->coef * boot->value;
    }
    Vec3 dir;
    Float pdf = 0.f;
    uint32_t j = 0;
    const Float u = rng.uniform();
    if (!neural_sample(y, u, Vec2(0.5f), &dir, &pdf, &j)) return 0.f;
    const Vec3 wi = to_local(v.bin_dirs[j]);
    const Float pmf = neural_site_pmf(y, j);
    const Float coef =
        luminance(bsdf_eval(b, wo_local, wi)) * fabsf(wi.z) * (4.f * kPi / static_cast<Float>(kNeuralBins)) / pmf;
    // Q is read only where it counts (a bin the BSDF does not reach need not be computed).
    *boot = GuideBootstrap{s, j, coef, coef > 0.f ? neural_site_q(v, y, j) : 0.f};
    return boot->value * boot->coef;
  }
  TESSERA_HOST_DEVICE bool record(int32_t s, uint32_t bin, Float target, const GuideBootstrap& boot) const {
    NeuralBootstrap nb;
    if (boot.slot >= 0) nb = NeuralBootstrap{&site[boot.slot], boot.bin, boot.coef, boot.value};
    return neural_record(v, site[s], bin, target, nb);
  }
  TESSERA_HOST_DEVICE void record_light(int32_t s, uint32_t li, Float learned) const {
    if (li < v.lights) neural_record(v, site[s], kNeuralBins + li, learned);
  }
  TESSERA_HOST_DEVICE void record_nee(int32_t, Float, Float) const {}
  // Vertices that sample with the scene's weight (not faded by a glossy lobe) inform it.
  TESSERA_HOST_DEVICE bool learns_mix(int32_t, Float guide_p) const {
    return v.sink != nullptr && v.learn_mix && guide_p == v.guide_prob;
  }
  TESSERA_HOST_DEVICE void record_mix(int32_t, const GuideMixSample& m, Float target) const { neural_record_mix(v, m, target); }
};

}  // namespace tessera
