// Read side of the guide cache, shared by CPU and CUDA kernels: find the
// spatial cell of a surface point, sample and evaluate the learned direction
// distribution, and record learning targets into the pass's accumulators.
//
// The field is frozen during a pass (values and distributions are read-only);
// updates go to integer accumulators with relaxed atomic adds, which makes
// their sums independent of thread, block and rank order. GuideField (host)
// folds them into the values between passes.
//
// Directions are bins of Clarberg's equal-area octahedral map over the full
// sphere in world space: every bin covers the same solid angle 4 pi / bins, so
// a bin's probability converts to a density with one multiplication, and the
// two sides of a thin wall (which see opposite hemispheres) never mix.
#pragma once

#include "kernels/distribution.h"
#include "kernels/equal_area.h"

namespace tessera {

// What a learning target estimates beyond the emitted radiance.
enum class GuideTarget : uint32_t {
  ExpectedSarsa = 0,  // the integral of Q f cos over the next vertex's bins (Dahm & Keller)
  QLearning = 1,      // the largest Q at the next vertex times the BSDF's albedo ("max" rule)
};

// Octree node over one normal class. Leaves own a cell; inner nodes have 8
// consecutive children starting at `child`, in octant order (bit 0 = x).
struct GuideNode {
  int32_t child = -1;
  int32_t cell = -1;
};

// Walker/Vose alias table entry of bin i: i is kept with probability `keep`,
// otherwise `alias` is taken. O(1) sampling where a cdf search would chase ~8
// dependent loads; the entry also carries the probabilities of i and of its
// alias, so a sample or a pdf lookup reads one 16-byte entry.
struct GuideAlias {
  Float keep = 1.f;
  uint32_t alias = 0;
  Float pmf = 0.f;        // probability of bin i
  Float alias_pmf = 0.f;  // probability of bin `alias`
};

// Per cell, after the bins and lights: the mean of next-event estimation's
// (unweighted) estimate of the light reflected at the cell's vertices, and of
// the learned estimate of the rest (the bins' integral), both per unit
// throughput, recorded at the same vertices. Their ratio sets nee_prob.
constexpr uint32_t kGuideNeeEntries = 2;

// Then, per cell, the learned mixture weight's statistics: for each candidate
// weight a_k, the mean over guided vertices of the estimator's second moment
// had the vertex sampled with a_k (importance-weighted from the weight it
// used), in units of the cell's own scale. The smallest one wins.
constexpr uint32_t kGuideMixEntries = 6;
TESSERA_HOST_DEVICE inline Float guide_mix_candidate(uint32_t k) { return 0.05f + 0.15f * static_cast<Float>(k); }

// Surface points are split by the dominant axis of their normal (+-x, +-y,
// +-z), so surfaces facing different ways never share a cell.
constexpr uint32_t kGuideNormalClasses = 6;

// Fixed-point scale for normals accumulated per cell (only their direction matters).
constexpr Float kGuideNormalScale = 1048576.f;

// The first levels of every octree, flattened: for each normal class, a grid
// of kGuideTopSide^3 equal cubes over the octree's cube, each holding the node
// that covers it at depth kGuideTopLevels (or the shallower leaf that does).
// Cell lookups start there instead of at the root.
constexpr uint32_t kGuideTopLevels = 3;
constexpr uint32_t kGuideTopSide = 1u << kGuideTopLevels;
constexpr uint32_t kGuideTopCells = kGuideTopSide * kGuideTopSide * kGuideTopSide;

struct GuideView {
  // Spatial octrees: nodes[0..5] are the roots of the normal classes; each
  // covers the cube [lo, lo + extent]^3.
  const GuideNode* nodes = nullptr;
  uint32_t num_nodes = 0;
  uint32_t num_cells = 0;  // entries of the per-cell arrays (copies to a device need them)
  // kGuideNormalClasses * kGuideTopCells node indices (null: start at the roots).
  const int32_t* top_nodes = nullptr;
  Vec3 lo{0.f};
  Float extent = 1.f;

  uint32_t grid = 12;      // bins per side of the equal-area square
  uint32_t bins = 144;     // grid * grid
  uint32_t lights = 0;     // learned light-selection entries per cell (0 = off)
  uint32_t stride = 152;   // entries per cell: bins, lights, kGuideNeeEntries, kGuideMixEntries
  uint32_t nee_entry = 144;  // first next-event statistic: bins + lights
  uint32_t mix_entry = 146;  // first mixture statistic: nee_entry + kGuideNeeEntries
  const Vec3* bin_dirs = nullptr;  // centre direction of each bin

  // Frozen per cell: values (incident radiance per bin, contribution per light),
  // cdfs of the sampling distributions, and what targets need.
  const Float* value = nullptr;        // cells * stride
  const GuideAlias* dir_alias = nullptr;  // cells * bins: per-cell alias tables of the direction distributions
  const Float* light_cdf = nullptr;    // cells * (lights + 1)
  const Float* irradiance = nullptr;   // cells: sum over bins of Q max(cos, 0) dOmega about the cell normal
  const Float* qmax = nullptr;         // cells: largest Q over the bins above the cell's surface
  const uint8_t* learn_normal = nullptr;  // cells: 1 while the cell's mean normal is still being estimated
  const Float* cell_light_prob = nullptr;  // cells: mixture weight of learned light selection (0: power only)
  // cells: probability that a vertex traces its next-event shadow ray. Below 1
  // where shadow rays have brought little of the light the cell reflects (a
  // room lit through a door gap: its light is almost always occluded). A
  // vertex that skips it counts as having selected no light, so the estimate
  // and the MIS weights stay unbiased (light pdfs carry this factor).
  const Float* nee_prob = nullptr;

  // Accumulators for the running pass: one block of acc_words integers that
  // starts at acc. Threads that share the block add with relaxed atomics; a
  // CPU thread whose view points into its own copy (acc_private) adds plainly.
  uint64_t* acc = nullptr;         // cells * stride pairs (sum in fixed point = target * fixed_scale, count)
  uint64_t* acc_normal = nullptr;  // cells * 3, fixed point (kGuideNormalScale)
  uint64_t* rejected = nullptr;    // [0] NaN/Inf/negative targets, [1] targets too large for the fixed point,
                                   // [2] mixture statistics out of the fixed point's range (not recorded)
  uint64_t acc_words = 0;          // size of the block: pairs, normals, rejections
  bool acc_private = false;        // the block is the calling thread's own (CPU only)
  Float fixed_scale = 1.f;
  Float max_target = 1e30f;        // larger targets are rejected (and counted), never clamped

  Float guide_prob = 0.5f;         // mixture weight of guided direction sampling (cells that have not learned one)
  const Float* cell_mix = nullptr; // cells: mixture weight of guided sampling (learned, or guide_prob)
  bool learn_mix = true;           // record the mixture statistics (off when the weight is fixed)
  GuideTarget target = GuideTarget::ExpectedSarsa;

  // Mixture weight of guided sampling in a cell. A cell that has learned no
  // light above its surface would sample the whole sphere uniformly, half of
  // it behind the surface: BSDF sampling does better until it has.
  TESSERA_HOST_DEVICE Float cell_guide_prob(int32_t cell) const { return learned(cell) ? cell_mix[cell] : 0.f; }
  // Whether a cell has learned any light above its surface (else it samples,
  // and predicts, nothing).
  TESSERA_HOST_DEVICE bool learned(int32_t cell) const { return irradiance[cell] > 0.f; }

  TESSERA_HOST_DEVICE Float bin_solid_angle() const { return 4.f * kPi / static_cast<Float>(bins); }
  // The alias entry of a bin, and the solid-angle density of guided sampling
  // for directions in that bin.
  TESSERA_HOST_DEVICE const GuideAlias* bin_entry(int32_t cell, uint32_t bin) const {
    return &dir_alias[static_cast<size_t>(cell) * bins + bin];
  }
  TESSERA_HOST_DEVICE Float entry_pdf(const GuideAlias& a) const {
    return a.pmf * (static_cast<Float>(bins) * kInv4Pi);
  }
  // The alias entry sample_bin(cell, u) reads first.
  TESSERA_HOST_DEVICE const GuideAlias* alias_entry(int32_t cell, Float u) const {
    return bin_entry(cell, glm::min(static_cast<uint32_t>(u * static_cast<Float>(bins)), bins - 1));
  }
  // Draws a bin with one uniform number (alias method); *pmf is its probability.
  TESSERA_HOST_DEVICE uint32_t sample_bin(int32_t cell, Float u, Float* pmf) const {
    Float x = u * static_cast<Float>(bins);
    uint32_t i = glm::min(static_cast<uint32_t>(x), bins - 1);
    const GuideAlias& a = *bin_entry(cell, i);
    const bool keep = (x - static_cast<Float>(i)) < a.keep;
    *pmf = keep ? a.pmf : a.alias_pmf;
    return keep ? i : a.alias;
  }
  TESSERA_HOST_DEVICE Distribution1DView light_distribution(int32_t cell) const {
    Distribution1DView d;
    d.cdf = light_cdf + static_cast<size_t>(cell) * (lights + 1);
    d.n = lights;
    return d;
  }
};

TESSERA_HOST_DEVICE inline uint32_t guide_normal_class(const Vec3& n) {
  Vec3 a = abs3(n);
  if (a.x >= a.y && a.x >= a.z) return n.x >= 0.f ? 0u : 1u;
  if (a.y >= a.z) return n.y >= 0.f ? 2u : 3u;
  return n.z >= 0.f ? 4u : 5u;
}

// One level of an octree descent: the octant of the cube (*lo, *size) that
// holds p; *lo and *size become that octant's.
TESSERA_HOST_DEVICE inline uint32_t guide_octant_step(const Vec3& p, Vec3* lo, Float* size) {
  *size *= 0.5f;
  const Vec3 mid = *lo + *size;
  const uint32_t octant = (p.x >= mid.x ? 1u : 0u) | (p.y >= mid.y ? 2u : 0u) | (p.z >= mid.z ? 4u : 0u);
  if (octant & 1u) lo->x = mid.x;
  if (octant & 2u) lo->y = mid.y;
  if (octant & 4u) lo->z = mid.z;
  return octant;
}

// The cell of a grid of n along one axis holding coordinate x (in cells),
// clamped to the grid. NaN (a degenerate hit) maps to 0: converting it to
// an integer would be undefined behaviour.
TESSERA_HOST_DEVICE inline uint32_t guide_grid_index(Float x, uint32_t n) {
  const Float last = static_cast<Float>(n - 1);
  return x > 0.f ? static_cast<uint32_t>(glm::min(x, last)) : 0u;
}

// The leaf cell holding point p on a surface whose normal (on the side the
// path is on) is n.
TESSERA_HOST_DEVICE inline int32_t guide_find_cell(const GuideView& g, const Vec3& p, const Vec3& n) {
  const uint32_t normal_class = guide_normal_class(n);
  Vec3 lo = g.lo;
  Float size = g.extent;
  const GuideNode* node = &g.nodes[normal_class];
  if (g.top_nodes) {
    // The octree's first levels in one step: the grid cube holding p (points
    // outside the cube go to the nearest one, as the descent would take them).
    size = g.extent * (1.f / static_cast<Float>(kGuideTopSide));
    const Vec3 rel = (p - g.lo) / size;
    const uint32_t ix = guide_grid_index(rel.x, kGuideTopSide);
    const uint32_t iy = guide_grid_index(rel.y, kGuideTopSide);
    const uint32_t iz = guide_grid_index(rel.z, kGuideTopSide);
    lo = g.lo + Vec3(static_cast<Float>(ix), static_cast<Float>(iy), static_cast<Float>(iz)) * size;
    node = &g.nodes[g.top_nodes[normal_class * kGuideTopCells + (iz * kGuideTopSide + iy) * kGuideTopSide + ix]];
  }
  while (node->child >= 0) node = &g.nodes[node->child + static_cast<int32_t>(guide_octant_step(p, &lo, &size))];
  return node->cell;
}

TESSERA_HOST_DEVICE inline uint32_t guide_bin_of(const GuideView& g, const Vec3& dir) {
  Vec2 uv = equal_area_sphere_to_square(dir);
  return guide_grid_index(uv.y * static_cast<Float>(g.grid), g.grid) * g.grid +
         guide_grid_index(uv.x * static_cast<Float>(g.grid), g.grid);
}

TESSERA_HOST_DEVICE inline Float guide_value(const GuideView& g, int32_t cell, uint32_t entry) {
  return g.value[static_cast<size_t>(cell) * g.stride + entry];
}

// Solid-angle density of guided sampling in cell for directions in bin.
TESSERA_HOST_DEVICE inline Float guide_bin_pdf(const GuideView& g, int32_t cell, uint32_t bin) {
  return g.entry_pdf(*g.bin_entry(cell, bin));
}
// Solid-angle density of guided sampling in cell for a unit world direction.
TESSERA_HOST_DEVICE inline Float guide_pdf(const GuideView& g, int32_t cell, const Vec3& dir) {
  return guide_bin_pdf(g, cell, guide_bin_of(g, dir));
}

// Draws a bin from the cell's distribution (u_bin) and a point within it (u),
// uniformly in area on the equal-area square, hence uniformly in solid angle.
// *bin receives the bin the direction lies in (for the learning update).
TESSERA_HOST_DEVICE inline bool guide_sample(const GuideView& g, int32_t cell, Float u_bin, Vec2 u, Vec3* dir,
                                             Float* pdf, uint32_t* bin_out) {
  Float pmf = 0.f;
  uint32_t bin = g.sample_bin(cell, u_bin, &pmf);
  if (!(pmf > 0.f)) return false;
  // The bin's row and column without integer division (a runtime divisor
  // costs tens of cycles on the hot path): (bin + 0.5) / grid is at least
  // 0.5 / grid from an integer, far beyond float rounding for grid <= 64.
  const Float inv_grid = 1.f / static_cast<Float>(g.grid);
  const uint32_t row = static_cast<uint32_t>((static_cast<Float>(bin) + 0.5f) * inv_grid);
  const uint32_t col = bin - row * g.grid;
  Vec2 sq((static_cast<Float>(col) + u.x) * inv_grid, (static_cast<Float>(row) + u.y) * inv_grid);
  *dir = equal_area_square_to_sphere(sq);  // unit length by construction
  // The density is the chosen bin's. Mapping the direction back could, for a
  // point within float rounding of a bin edge, land in the neighbour: that
  // set has measure ~1e-7 of the sphere and is not worth a second mapping.
  *bin_out = bin;
  *pdf = pmf * (static_cast<Float>(g.bins) * kInv4Pi);
  return true;
}

// Adds v to an accumulator of the view's block.
TESSERA_HOST_DEVICE inline void guide_acc_add(const GuideView& g, uint64_t* p, uint64_t v) {
#if TESSERA_IS_GPU_CODE
  atomic_add_u64(p, v);
#else
  if (g.acc_private) *p += v;
  else atomic_add_u64(p, v);
#endif
}

// Adds one learning target to entry (a bin, or bins + light) of a cell.
// Returns false (and counts it) when the target is rejected. Out of line on
// the GPU: learning only, called from every learning hook.
TESSERA_HOST_DEVICE TESSERA_DEVICE_NOINLINE inline bool guide_record(const GuideView& g, int32_t cell, uint32_t entry,
                                                                     Float target) {
  if (!(target >= 0.f) || !(target <= 3.4e38f)) {  // NaN, negative or infinite
    guide_acc_add(g, &g.rejected[0], 1);
    return false;
  }
  if (target > g.max_target) {
    guide_acc_add(g, &g.rejected[1], 1);
    return false;
  }
  size_t i = static_cast<size_t>(cell) * g.stride + entry;
  // float is exact enough here: targets are below 2^44 units, rounded to 24 bits.
  guide_acc_add(g, &g.acc[2 * i], static_cast<uint64_t>(target * g.fixed_scale + 0.5f));
  guide_acc_add(g, &g.acc[2 * i + 1], 1);
  return true;
}

// Accumulates the normal of a point that learned into the cell: the cell's
// mean normal orients its cosine weighting.
TESSERA_HOST_DEVICE inline void guide_record_normal(const GuideView& g, int32_t cell, const Vec3& n) {
  if (!g.learn_normal[cell]) return;
  uint64_t* a = g.acc_normal + 3 * static_cast<size_t>(cell);
  for (int k = 0; k < 3; ++k)
    guide_acc_add(g, &a[k], static_cast<uint64_t>(static_cast<int64_t>(n[k] * kGuideNormalScale)));
}

}  // namespace tessera
