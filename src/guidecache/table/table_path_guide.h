// The Q-table's per-path guide (guidecache/path_guide.h) over its GuideView.
#pragma once

#include "guidecache/path_guide.h"
#include "guidecache/table/guiding.h"

namespace tessera {

struct TablePathGuide {
  const GuideView& g;
  PendingTarget pending;
  TESSERA_HOST_DEVICE explicit TablePathGuide(const GuideView& view) : g(view) {}
  TablePathGuide(const GuideView&&) = delete;  // it keeps a reference: not to a temporary
  // Light selection and next-event probability are learned per cell.
  TESSERA_HOST_DEVICE Float nee_probability(int32_t cell) const { return tessera::nee_probability(&g, cell); }
  // Probability that next-event estimation at `cell` (-1: none, as in a
  // medium) traces a shadow ray to light li, and the draw of that light.
  TESSERA_HOST_DEVICE Float light_pmf(const SceneView& s, const LightQuery& q, int32_t cell, uint32_t li) const {
    return light_select_pmf(s, q, &g, cell, li);
  }
  TESSERA_HOST_DEVICE uint32_t pick_light(const SceneView& s, const LightQuery& q, int32_t cell, Float u,
                                          Float* pmf) const {
    return select_light(s, q, &g, cell, u, pmf);
  }

  TESSERA_HOST_DEVICE bool locates(int32_t, int32_t) const { return true; }
  TESSERA_HOST_DEVICE int32_t locate(const Vec3& p, const Vec3& n_side) { return guide_find_cell(g, p, n_side); }
  TESSERA_HOST_DEVICE bool reused_site() const { return false; }
  TESSERA_HOST_DEVICE void at_medium_vertex() {}
  TESSERA_HOST_DEVICE uint32_t bins() const { return g.bins; }
  TESSERA_HOST_DEVICE Vec3 bin_dir(uint32_t j) const { return g.bin_dirs[j]; }
  TESSERA_HOST_DEVICE Float irradiance(int32_t cell) const { return g.irradiance[cell]; }
  TESSERA_HOST_DEVICE void note_normal(int32_t cell, const Vec3& n_side) const { guide_record_normal(g, cell, n_side); }
  TESSERA_HOST_DEVICE bool learned(int32_t cell) const { return g.learned(cell); }
  TESSERA_HOST_DEVICE Float probability(int32_t cell, const BsdfParams& b, bool lambertian_only) const {
    return guide_probability(g, cell, b, lambertian_only);
  }
  TESSERA_HOST_DEVICE void prefetch_sample(int32_t cell, Float uc) const { TESSERA_PREFETCH(g.alias_entry(cell, uc)); }
  // The guide's density of a direction in two steps, so that its memory is
  // fetched while a shadow ray is traced: lookup, then density.
  using DirLookup = const GuideAlias*;
  TESSERA_HOST_DEVICE DirLookup lookup(int32_t cell, const Vec3& dir) const {
    const GuideAlias* e = g.bin_entry(cell, guide_bin_of(g, dir));
    TESSERA_PREFETCH(e);
    return e;
  }
  TESSERA_HOST_DEVICE Float lookup_pdf(DirLookup e) const { return g.entry_pdf(*e); }
  TESSERA_HOST_DEVICE bool sample(int32_t cell, Float u_bin, Vec2 u, Vec3* dir, Float* pdf, uint32_t* bin) const {
    return guide_sample(g, cell, u_bin, u, dir, pdf, bin);
  }
  TESSERA_HOST_DEVICE uint32_t bin_of(const Vec3& dir) const { return guide_bin_of(g, dir); }
  TESSERA_HOST_DEVICE Float bin_pdf(int32_t cell, uint32_t bin) const { return guide_bin_pdf(g, cell, bin); }
  TESSERA_HOST_DEVICE Float value(int32_t cell, uint32_t bin) const { return guide_value(g, cell, bin); }
  TESSERA_HOST_DEVICE Float survival(int32_t cell, uint32_t bin, Float throughput, Float path_expected, Float window) const {
    return guided_survival(g, cell, bin, throughput, path_expected, window);
  }
  template <class ToLocal>
  TESSERA_HOST_DEVICE Float bins_integral(int32_t cell, const BsdfParams& b, bool lambertian, Vec3 wo_local,
                                          const ToLocal& to_local, PixelSampler& rng, GuideBootstrap*) const {
    return guide_bins_integral(g, cell, b, lambertian, wo_local, to_local, rng);
  }
  TESSERA_HOST_DEVICE bool record(int32_t cell, uint32_t bin, Float target, const GuideBootstrap&) const {
    return guide_record(g, cell, bin, target);
  }
  TESSERA_HOST_DEVICE void record_light(int32_t cell, uint32_t li, Float learned) const {
    if (g.lights > 0) guide_record(g, cell, g.bins + li, learned);
  }
  TESSERA_HOST_DEVICE void record_nee(int32_t cell, Float direct, Float indirect) const {
    guide_record(g, cell, g.nee_entry, direct);
    guide_record(g, cell, g.nee_entry + 1, indirect);
  }
  // Whether a vertex sampled with weight guide_p informs its cell's mixture weight.
  TESSERA_HOST_DEVICE bool learns_mix(int32_t cell, Float guide_p) const {
    return g.learn_mix && guide_p == g.cell_guide_prob(cell);
  }
  TESSERA_HOST_DEVICE void record_mix(int32_t cell, const GuideMixSample& m, Float target) const {
    guide_record_mix(g, cell, m, target);
  }
};

}  // namespace tessera
