// A path's guide learning (Dahm & Keller's targets), as hooks the
// integrator's stages call on the path's guide (path_guide.h), whose
// PendingTarget holds the one target in flight. Each traced segment x -> y
// sends Le(y) + (integral of Q f cos at y) to x's cell, and each shadow ray
// sends its unoccluded contribution to the light-selection entry of x's cell.
//
// With next-event estimation the field learns the radiance NEE does not
// deliver: emission that NEE samples is left out of the targets and the light
// reflected at y directly is added from y's own (unweighted) NEE estimate.
// Guided directions then go where indirect light comes from instead of
// duplicating the light samples; Q stays the full reflected radiance, so
// light that reaches x over several bounces is still learned.
//
// Learning runs in some passes only, and mostly writes to memory: the
// hooks that record (learning_commit, learning_at_surface,
// learning_at_scatter) are out of line on the GPU (device.h), outside the
// path loop's register allocation.
#pragma once

#include "guidecache/path_guide.h"

namespace tessera {

// Sends the pending target (and its mixture statistics) to x's cell, after
// the medium's weight on the segment (segment_tr). boot: the target's
// bootstrapped part (the network refreshes it as it trains). `updates`
// counts the targets the guide accepted.
template <class PG>
TESSERA_HOST_DEVICE TESSERA_COLD_STAGE void learning_commit(PG& pg, Float target, GuideBootstrap boot, Float segment_tr,
                                                            uint64_t& updates) {
  PendingTarget& t = pg.pending;
  target *= segment_tr;
  boot.coef *= segment_tr;
  if (pg.record(t.cell, t.bin, target, boot)) {
    ++updates;
    if (t.mix.mix_pdf > 0.f) {
      t.mix.emitted *= segment_tr;
      pg.record_mix(t.cell, t.mix, target);
    }
  }
}

// MIS-weighted emission met by the pending direction, for its mixture
// statistics (several environments: their luminances add, and the density
// is their luminance-weighted mean).
template <class PG>
TESSERA_HOST_DEVICE TESSERA_INLINE void learning_note_emission(PG& pg, Float le, Float light_pdf) {
  PendingTarget& t = pg.pending;
  if (t.cell < 0 || !(t.mix.mix_pdf > 0.f) || !(le > 0.f)) return;
  const Float total = t.mix.emitted + le;
  t.mix.light_pdf = (t.mix.light_pdf * t.mix.emitted + light_pdf * le) / total;
  t.mix.emitted = total;
}

// The path left the scene: the pending target gets the environment's
// radiance where NEE could not have delivered it (le_counted), else nothing.
template <class PG>
TESSERA_HOST_DEVICE TESSERA_INLINE void learning_at_escape(PG& pg, Float le_counted, Float segment_tr, uint64_t& updates) {
  if (pg.pending.cell >= 0) learning_commit(pg, le_counted, GuideBootstrap{}, segment_tr, updates);
}

// The guide has no cells in media: a pending target ends at a medium vertex
// with the light scattered there directly (multiple scattering is not learned).
template <class PG>
TESSERA_HOST_DEVICE TESSERA_INLINE void learning_at_medium_vertex(PG& pg, Float direct_estimate, Float segment_tr,
                                                          uint64_t& updates) {
  if (pg.pending.cell < 0) return;
  learning_commit(pg, direct_estimate, GuideBootstrap{}, segment_tr, updates);
  pg.pending.cell = -1;
}

// A surface vertex y was located: what its hit tells the pending target.
// Emission the integrator weights by MIS is NEE's to deliver.
template <class PG>
TESSERA_HOST_DEVICE TESSERA_COLD_STAGE void learning_at_surface(PG& pg, int32_t cell, const Vec3& n_side,
                                                                Float le_unweighted, bool delta_lobe) {
  pg.note_normal(cell, n_side);
  pg.pending.le = le_unweighted;
  pg.pending.at_delta = delta_lobe;
}

// The vertex at `cell` took its direction (bin `bin`, BSDF weight `weight`
// luminance): a delta vertex completes the pending target with the value of
// the direction it took; the new segment's target becomes the pending one.
// mix: the vertex's mixture statistics (mix_pdf 0: it does not inform the weight).
template <class PG>
TESSERA_HOST_DEVICE TESSERA_COLD_STAGE void learning_at_scatter(PG& pg, int32_t cell, uint32_t bin, Float weight,
                                                                const GuideMixSample& mix, Float segment_tr,
                                                                uint64_t& updates) {
  PendingTarget& t = pg.pending;
  if (t.at_delta && t.cell >= 0) {
    const Float value = pg.value(cell, bin);
    learning_commit(pg, t.le + value * weight, GuideBootstrap{cell, bin, weight, value}, segment_tr, updates);
  }
  t.cell = cell;
  t.bin = bin;
  t.at_delta = false;
  t.mix = mix;
}

}  // namespace tessera
