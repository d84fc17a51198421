// Read side of the neural guide, shared by CPU and device code: a small MLP
// over a multi-resolution hash-grid encoding of position (Müller et al.
// 2022) plus the surface normal, whose 144 outputs are the log incident
// radiance of the same equal-area direction bins as the Q-table's
// (guide_view.h). One inference per path vertex fills a NeuralSite: the
// bins' radiance Q, the guided distribution (Q x max(cos, 0) about the
// vertex's normal, mixed with a uniform floor; its cdf is built by the
// first sample), the irradiance and the largest Q: everything the
// integrator reads from a Q-table cell, so sampling, the mixture, the floor,
// the expected-SARSA targets and guided roulette carry over unchanged. In scenes of kNeuralMinLights to
// kNeuralMaxLights lights the network has one more output per light, the
// contribution next-event estimation gets from it at the point (the table's
// learned light selection, kept as its cells keep it).
//
// Plain loops over float arrays, no host types: the same code runs on a GPU.
// Weights are frozen during a pass (the host trains between passes,
// guidecache/neural_guide.h); learning targets go to a per-thread sink.
#pragma once

#include <cstring>

#include "kernels/equal_area.h"
#include "kernels/lanes8.h"
#include "kernels/vecmath.h"

namespace tessera {

constexpr uint32_t kNeuralGrid = 12;                       // bins per side, as the table's default
constexpr uint32_t kNeuralBins = kNeuralGrid * kNeuralGrid;  // 144
// The network numbers its bins tile by tile: the 12x12 equal-area square is
// cut into 18 tiles of 2 rows x 4 columns, numbered row-major, each tile's
// bins row-major. A tile is one block of kLanes8 outputs in an inference,
// and it is compact on the sphere, so that more tiles than blocks of 8
// consecutive row-major bins lie wholly below a surface and are skipped
// (neural_infer): on axis-aligned normals 4 to 9 of 18 instead of 0 to 9,
// and twice as many on average over all normals. (The table numbers its
// bins row-major: guide_view.h.)
constexpr uint32_t kNeuralTileRows = 2, kNeuralTileCols = 4;
constexpr uint32_t kNeuralTile = kNeuralTileRows * kNeuralTileCols;       // bins per tile
constexpr uint32_t kNeuralTiles = kNeuralBins / kNeuralTile;               // 18
constexpr uint32_t kNeuralTilesPerRow = kNeuralGrid / kNeuralTileCols;     // 3
static_assert(kNeuralGrid % kNeuralTileRows == 0 && kNeuralGrid % kNeuralTileCols == 0, "whole tiles");
// The network's number of the bin in row `row`, column `col` of the square.
TESSERA_HOST_DEVICE constexpr uint32_t neural_bin_at(uint32_t row, uint32_t col) {
  return ((row / kNeuralTileRows) * kNeuralTilesPerRow + col / kNeuralTileCols) * kNeuralTile +
         (row % kNeuralTileRows) * kNeuralTileCols + col % kNeuralTileCols;
}
TESSERA_HOST_DEVICE constexpr uint32_t neural_bin_row(uint32_t bin) {
  return bin / kNeuralTile / kNeuralTilesPerRow * kNeuralTileRows + bin % kNeuralTile / kNeuralTileCols;
}
TESSERA_HOST_DEVICE constexpr uint32_t neural_bin_col(uint32_t bin) {
  return bin / kNeuralTile % kNeuralTilesPerRow * kNeuralTileCols + bin % kNeuralTileCols;
}
constexpr uint32_t kNeuralLevels = 8;                      // hash-grid levels
constexpr uint32_t kNeuralFeatures = 2;                    // features per level
// Entries per level: 2^table_log2 (NeuralGuideConfig::table_log2), within
// these bounds (at 2^16 the state is 12 MB, and every training thread holds
// a gradient of that size).
constexpr uint32_t kNeuralMinTableLog2 = 8, kNeuralMaxTableLog2 = 16;
constexpr uint32_t kNeuralEncoded = kNeuralLevels * kNeuralFeatures;
constexpr uint32_t kNeuralInputs = kNeuralEncoded + 3;     // encoding, then the normal
constexpr uint32_t kNeuralMaxWidth = 64;
// Light selection is learned in scenes of this many lights (a single quad
// light is two: the table's rule); each is one more output.
constexpr uint32_t kNeuralMinLights = 3, kNeuralMaxLights = 16;
constexpr uint32_t kNeuralMaxOutputs = kNeuralBins + kNeuralMaxLights;
// Share of light selections drawn from the learned distribution once it has
// seen light (the rest by power, as the table's GuideConfig::light_guide_prob).
constexpr Float kNeuralLightGuideProb = 0.9f;
// Network outputs are clamped here before exp(): a prediction never
// overflows, and a bin is never exactly zero.
constexpr Float kNeuralMinLog = -30.f, kNeuralMaxLog = 20.f;

// Offsets of the parameter blocks in one flat float array (outputs: the
// direction bins, then one per learned light). Weight matrices
// are stored input-major (w[i * out + o]), so that a layer is a sum of
// scaled columns: contiguous, independent lanes that compilers vectorise
// without reassociating sums.
struct NeuralLayout {
  uint32_t width;
  uint32_t table_log2;  // entries per hash-grid level: 2^table_log2
  uint32_t lights;      // learned lights: 0 or kNeuralMinLights..kNeuralMaxLights
  TESSERA_HOST_DEVICE NeuralLayout(uint32_t width_, uint32_t table_log2_, uint32_t lights_)
      : width(width_), table_log2(table_log2_), lights(lights_) {}
  TESSERA_HOST_DEVICE uint32_t table_size() const { return 1u << table_log2; }
  TESSERA_HOST_DEVICE uint32_t outputs() const { return kNeuralBins + lights; }
  TESSERA_HOST_DEVICE uint32_t grid() const { return 0; }
  TESSERA_HOST_DEVICE uint32_t w1() const { return kNeuralLevels * table_size() * kNeuralFeatures; }
  TESSERA_HOST_DEVICE uint32_t b1() const { return w1() + kNeuralInputs * width; }
  TESSERA_HOST_DEVICE uint32_t w2() const { return b1() + width; }
  TESSERA_HOST_DEVICE uint32_t b2() const { return w2() + width * width; }
  TESSERA_HOST_DEVICE uint32_t w3() const { return b2() + width; }
  TESSERA_HOST_DEVICE uint32_t b3() const { return w3() + width * outputs(); }
  TESSERA_HOST_DEVICE uint32_t size() const { return b3() + outputs(); }
};

// One learning target, as the integrator records it: the point and normal
// of the vertex, the output it trains (the bin of the direction it took, or
// kNeuralBins + a light) and the target (radiance arriving along it, or
// what the light's sample brought, in the scene's units).
//
// Most targets are partly bootstrapped: target = known + coef x value, the
// value being what the network predicted at the next vertex y (its
// irradiance, y_bin == kNeuralIrradiance, or Q of bin y_bin) when the path
// was traced. Training recomputes that value with the network as it is at
// each optimiser step (NeuralGuide::tile_gradient), so that every step is a
// bootstrap step, not only every pass. coef 0: nothing bootstrapped.
constexpr uint32_t kNeuralIrradiance = 0xffffffffu;
struct NeuralTrainingSample {
  float p[3];
  float n[3];
  uint32_t bin;
  float target;
  float y_p[3] = {0.f, 0.f, 0.f};
  float y_n[3] = {0.f, 0.f, 0.f};
  uint32_t y_bin = 0;
  float coef = 0.f;
  float value = 0.f;
};

// Where learning targets go while a tile renders: on the CPU one sink per
// thread and tile (data: the tile's buffer), on a device one per path (data:
// the path's kNeuralPathTargets slots; render/device_tiles.h). A target is
// kept with probability keep_prob, decided by a hash of (tile, path, its
// number in the path): deterministic, whichever thread, rank or device
// renders the path. A path keeps at most kNeuralPathTargets (the rest are
// dropped and counted), and beyond `capacity` the rest are dropped too:
// both rules are the same on every backend, so a device's targets equal
// the CPU's (the device applies the tile's capacity when it gathers them).
constexpr uint32_t kNeuralPathTargets = 8;
// The mixture weight is learned for the whole scene: the candidate under
// which the learning vertices' estimates have the smallest summed second
// moment (neural_record_mix in path_guide.h, NeuralGuide::mix_weight),
// among the table's per-cell candidates (guide_mix_candidate) from
// kNeuralMixFirstCandidate on: 0.5, 0.65 or 0.8. Lower weights are not
// candidates: a vertex's second moment sees one bounce, the weight's effect
// on whole paths was larger than it predicts, and no weight below 0.5 was
// measured to gain on the shipped scenes (docs/neural-guide.md).
constexpr uint32_t kNeuralMixFirstCandidate = 3;
constexpr uint32_t kNeuralMixCandidates = 3;
// Second moments in units of 2^-20 of the output scale squared; one
// vertex's sum over the candidates at most 2^12 (2^32 units): 2^32
// vertices at the cap before a sum could overflow.
constexpr Float kNeuralMixMomentUnit = 1.f / 1048576.f;
constexpr Float kNeuralMixVertexCap = 4096.f;
struct NeuralSampleSink {
  NeuralTrainingSample* data = nullptr;
  uint32_t capacity = 0;
  uint32_t count = 0;
  uint32_t tile = 0;
  uint32_t path = 0;            // hash of (pixel, sample index) of the path being traced
  uint32_t seen = 0;            // targets this path offered (accepted by the checks below)
  uint32_t path_kept = 0;       // targets this path kept
  Float keep_prob = 1.f;
  uint64_t rejected_nonfinite = 0;  // NaN, Inf or negative targets
  uint64_t rejected_large = 0;      // targets beyond max_target
  uint64_t dropped = 0;             // kept targets beyond capacity
  // The mixture statistics: per candidate weight (from
  // kNeuralMixFirstCandidate), the learning vertices' summed second moments
  // (kNeuralMixMomentUnit), and how many vertices gave theirs. Integers:
  // the sums do not depend on the order.
  uint64_t mix_moments[kNeuralMixCandidates] = {};
  uint64_t mix_vertices = 0;
  uint64_t mix_rejected = 0;  // vertices whose statistics were NaN or overflowed (left out)
};

struct NeuralGuideView {
  const float* params = nullptr;  // NeuralLayout{width, table_log2, lights} blocks
  uint32_t width = 8;             // NeuralGuide::view fills every field; these are NeuralGuideConfig's defaults
  uint32_t table_log2 = 11;
  uint32_t lights = 0;            // learned lights (NeuralLayout::lights): the scene's lights 0..lights-1
  Vec3 lo{0.f};                   // the encoded cube: [lo, lo + extent]^3 (the scene's bounds)
  Float extent = 1.f;
  Float reuse_radius = 0.f;       // NeuralFirstSite's (path_guide.h), from NeuralGuideConfig::reuse_cells
  Float scale = 1.f;              // Q = scale * exp(output)
  Float guide_prob = 0.5f;        // mixture weight of guided sampling once the network has trained
  Float floor = 0.02f;            // share of each distribution spread uniformly
  bool trained = false;           // no optimiser step yet: nothing to guide with
  bool learn_mix = true;          // record the mixture statistics (off when the weight is fixed)
  Float max_target = 3.4e38f;     // larger targets are rejected (and counted), never clamped
  const Vec3* bin_dirs = nullptr;  // kNeuralBins centre directions, in the network's numbering (tiles)
  const Float* bin_dir_soa = nullptr;  // the same, as x[kNeuralBins], y[...], z[...] (a loop over bins vectorises)
  uint32_t tile_targets = 256;    // learning targets a tile keeps on average (NeuralSampleSink::keep_prob)
  NeuralSampleSink* sink = nullptr;  // the calling thread's (null: targets are not recorded)
};

// The network's answer at one vertex.
struct NeuralSite {
  Vec3 p{0.f}, n{0.f, 0.f, 1.f};
  // Incident radiance per bin, then each learned light's contribution. Not
  // set in the tiles of bins that lie wholly below the surface (bit t of
  // `skipped`: bins 8t..8t+7): read Q through neural_site_q.
  Float q[kNeuralMaxOutputs];
  uint32_t skipped = 0;
  Float h2[kNeuralMaxWidth];  // the last hidden layer: a skipped bin's Q is one output from it
  // The guided distribution per bin, before normalisation: Q x max(cos, 0)
  // (0 in skipped tiles). A bin's probability is weight x pmf_scale +
  // pmf_floor (read it through neural_site_pmf): normalised when read, not
  // for all 144 bins at every vertex.
  Float weight[kNeuralBins];
  Float pmf_scale = 0.f, pmf_floor = 0.f;
  // Inclusive running sum of the tiles' probabilities (kNeuralTile bins each), the
  // last 1: built by the first sample (neural_build_cdf).
  Float tile_cdf[kNeuralTiles];
  bool has_cdf = false;
  Float irradiance = 0.f;    // sum over bins of Q max(cos, 0) dOmega about n
  Float qmax = 0.f;          // largest Q over bins above the surface
  // Learned light selection: the share of selections drawn from light_cdf
  // (0: by power alone: no learned lights, or before the first optimiser
  // step; then kNeuralLightGuideProb everywhere, where the table waits for
  // a cell's first light target).
  Float light_prob = 0.f;
  Float light_pmf[kNeuralMaxLights];
  Float light_cdf[kNeuralMaxLights];  // inclusive running sum of light_pmf, the last 1
};

// e^x for the network's outputs, clamped to [kNeuralMinLog, kNeuralMaxLog]:
// t = x log2(e) = n + f with |f| <= 1/2, 2^f by a degree-5 polynomial
// (minimax for relative error, fitted for this; below 2e-7 in float, and
// below 2e-6 for e^x over the whole range, where rounding t dominates),
// 2^n from the exponent bits. A loop over bins of it vectorises, which
// libm's expf does not, and it is the same function on every machine. The
// reduction in base 2 needs no n ln2 product, and the polynomial is a
// degree lower than e^f's Taylor series of equal accuracy.
TESSERA_HOST_DEVICE inline Float neural_exp(Float x) {
  x = x > kNeuralMinLog ? x : kNeuralMinLog;  // selects, not branches (NaN -> the minimum)
  x = x < kNeuralMaxLog ? x : kNeuralMaxLog;
  const Float t = x * 1.44269504f;
  // round(t): truncation of a positive number (offset by 128) is its floor.
  const int32_t n = static_cast<int32_t>(t + 128.5f) - 128;
  const Float f = t - static_cast<Float>(n);
  const Float p =
      1.f + f * (0.693147004f + f * (0.240222424f + f * (0.0555073358f + f * (0.00967151299f + f * 0.00132647203f))));
  const uint32_t bits = static_cast<uint32_t>(n + 127) << 23;
  Float scale;
  memcpy(&scale, &bits, sizeof scale);
  return p * scale;
}

// neural_exp on eight lanes: the same operations, the same bits.
TESSERA_LANES_FN F8 neural_exp8(F8 x) {
  const F8 lo = lanes_splat(kNeuralMinLog), hi = lanes_splat(kNeuralMaxLog);
  x = lanes_select_gt(x, lo, x, lo);
  x = lanes_select_gt(hi, x, x, hi);
  const F8 t = x * 1.44269504f;
  const I8 n = lanes_trunc_i(t + 128.5f) - 128;
  const F8 f = t - lanes_float_i(n);
  const F8 p =
      1.f + f * (0.693147004f + f * (0.240222424f + f * (0.0555073358f + f * (0.00967151299f + f * 0.00132647203f))));
  return p * lanes_bits_to_float(lanes_u(n + 127) << 23u);
}

// Cells per side of each level: geometric from 4 to 256 (4 * 64^(l / 7), rounded).
TESSERA_HOST_DEVICE inline uint32_t neural_level_resolution(uint32_t level) {
  const uint32_t res[kNeuralLevels] = {4, 7, 13, 24, 43, 78, 141, 256};
  return res[level];
}

// Entry of grid vertex (x, y, z) in a level's table of table_size (a power
// of two) entries, at a level with res cells per side: dense while the
// level's vertices fit the table, hashed beyond (the primes of Teschner et
// al., as instant-ngp).
TESSERA_HOST_DEVICE inline uint32_t neural_grid_entry(uint32_t table_size, uint32_t res, uint32_t x, uint32_t y,
                                                      uint32_t z) {
  const uint32_t side = res + 1;
  if (side * side * side <= table_size) return (z * side + y) * side + x;
  return (x ^ (y * 2654435761u) ^ (z * 805459861u)) & (table_size - 1);
}

// Position in the unit cube of the encoding (clamped: points on or beyond the bounds).
TESSERA_HOST_DEVICE inline Vec3 neural_unit_position(const NeuralGuideView& v, const Vec3& p) {
  const Vec3 u = (p - v.lo) / v.extent;
  auto clamp01 = [](Float x) { return x > 0.f ? glm::min(x, 1.f) : 0.f; };  // NaN -> 0
  return Vec3(clamp01(u.x), clamp01(u.y), clamp01(u.z));
}

// The 8 grid vertices around unit position u at a level and their
// trilinear weights: the plain definition of what neural_corners8 computes
// for all levels at once (tested against it).
TESSERA_HOST_DEVICE inline void neural_level_corners(uint32_t table_size, uint32_t level, const Vec3& u, uint32_t entry[8],
                                                     Float weight[8]) {
  const uint32_t res = neural_level_resolution(level);
  const Vec3 x = u * static_cast<Float>(res);
  uint32_t i0[3];
  Float f[3];
  for (int k = 0; k < 3; ++k) {
    i0[k] = glm::min(static_cast<uint32_t>(x[k]), res - 1);
    f[k] = x[k] - static_cast<Float>(i0[k]);
  }
  for (uint32_t c = 0; c < 8; ++c) {
    const uint32_t dx = c & 1u, dy = (c >> 1) & 1u, dz = (c >> 2) & 1u;
    entry[c] = neural_grid_entry(table_size, res, i0[0] + dx, i0[1] + dy, i0[2] + dz);
    weight[c] = (dx ? f[0] : 1.f - f[0]) * (dy ? f[1] : 1.f - f[1]) * (dz ? f[2] : 1.f - f[2]);
  }
}

// neural_level_corners at every level side by side (lanes8.h): corner c's
// entry in each level's table (lane l: level l) and its trilinear weight.
TESSERA_HOST_DEVICE inline void neural_corners8(uint32_t table_size, const Vec3& u, U8 entry[8], F8 weight[8]) {
  static_assert(kNeuralLevels == kLanes8, "one lane per level");
  uint32_t res_list[kLanes8];
  for (uint32_t l = 0; l < kLanes8; ++l) res_list[l] = neural_level_resolution(l);
  const U8 res = lanes_make_u(res_list);
  const U8 side = res + 1u;
  // Levels whose vertices fit the table index it densely (neural_grid_entry).
  const U8 vertices = side * side * side, entries = lanes_splat_u(table_size);
  U8 i0[3];
  F8 f[3], g[3];
  for (int k = 0; k < 3; ++k) {
    const F8 x = lanes_splat(u[k]) * lanes_float(res);
    i0[k] = lanes_min_u(lanes_trunc_u(x), res - 1u);
    f[k] = x - lanes_float(i0[k]);
    g[k] = 1.f - f[k];
  }
  for (uint32_t c = 0; c < 8; ++c) {
    const uint32_t dx = c & 1u, dy = (c >> 1) & 1u, dz = (c >> 2) & 1u;
    const U8 x = i0[0] + dx, y = i0[1] + dy, z = i0[2] + dz;
    entry[c] = lanes_select_le_u(vertices, entries, (z * side + y) * side + x,
                                 (x ^ (y * 2654435761u) ^ (z * 805459861u)) & (table_size - 1u));
    weight[c] = (dx ? f[0] : g[0]) * (dy ? f[1] : g[1]) * (dz ? f[2] : g[2]);
  }
}

// The network's input for a point and normal: kNeuralInputs floats, each
// level's features summed over its corners in their order.
TESSERA_HOST_DEVICE inline void neural_encode(const NeuralGuideView& v, const Vec3& p, const Vec3& n, Float* in) {
  static_assert(kNeuralFeatures == 2, "two features per level");
  const uint32_t table_size = 1u << v.table_log2;
  U8 entry[8];
  F8 weight[8];
  neural_corners8(table_size, neural_unit_position(v, p), entry, weight);
  F8 f0 = lanes_splat(0.f), f1 = lanes_splat(0.f);
  for (uint32_t c = 0; c < 8; ++c) {
    F8 t0, t1;
    for (uint32_t l = 0; l < kLanes8; ++l) {
      const float* e = v.params + (static_cast<size_t>(l) * table_size + entry[c][l]) * kNeuralFeatures;
      t0[l] = e[0];
      t1[l] = e[1];
    }
    f0 += weight[c] * t0;
    f1 += weight[c] * t1;
  }
  for (uint32_t l = 0; l < kLanes8; ++l) {
    in[l * kNeuralFeatures] = f0[l];
    in[l * kNeuralFeatures + 1] = f1[l];
  }
  in[kNeuralEncoded] = n.x;
  in[kNeuralEncoded + 1] = n.y;
  in[kNeuralEncoded + 2] = n.z;
}

// out[o] = max(b[o] + sum_i w[i * outs + o] in[i], 0): a hidden layer,
// in blocks of 8 outputs where the width allows (each output's sum in the
// same order either way; a NaN sum gives 0). No test for zero inputs:
// ReLU zeros fall at random, and the mispredicted branches cost more than
// the columns they skip.
TESSERA_HOST_DEVICE inline void neural_hidden_layer(const float* w, const float* b, const Float* in, uint32_t ins,
                                                    uint32_t outs, Float* out) {
  const uint32_t blocked = outs - outs % kLanes8;
  const F8 zero = lanes_splat(0.f);
  for (uint32_t o = 0; o < blocked; o += kLanes8) {
    F8 acc = lanes_load(b + o);
    const float* col = w + o;
    for (uint32_t i = 0; i < ins; ++i, col += outs) acc += lanes_load(col) * in[i];
    lanes_store(out + o, lanes_select_gt(acc, zero, acc, zero));
  }
  for (uint32_t o = blocked; o < outs; ++o) {
    Float acc = b[o];
    for (uint32_t i = 0; i < ins; ++i) acc += w[static_cast<size_t>(i) * outs + o] * in[i];
    out[o] = acc > 0.f ? acc : 0.f;
  }
}

// The learned light selection from the light outputs (the table's rule):
// lights in proportion to their predicted contribution, mixed with the
// uniform floor; drawn with probability kNeuralLightGuideProb, by power
// otherwise. An untrained network leaves selection to power alone (as
// would non-finite predictions, which the clamped exp rules out).
TESSERA_HOST_DEVICE inline void neural_light_distribution(const NeuralGuideView& v, NeuralSite* site) {
  site->light_prob = 0.f;
  const uint32_t lights = v.lights <= kNeuralMaxLights ? v.lights : 0u;
  Float* c = site->q + kNeuralBins;
  // exp on lanes, eight lights at a time (neural_exp8: the bits of neural_exp).
  for (uint32_t i = 0; i < lights; i += kLanes8) {
    F8 x = lanes_splat(0.f);
    for (uint32_t k = 0; k < kLanes8 && i + k < lights; ++k) x[k] = c[i + k];
    const F8 e = neural_exp8(x);
    for (uint32_t k = 0; k < kLanes8 && i + k < lights; ++k) c[i + k] = v.scale * e[k];
  }
  Float total = 0.f;
  for (uint32_t i = 0; i < lights; ++i) total += c[i];
  if (lights == 0 || !v.trained || !(total > 0.f) || !(total <= 3.4e38f)) return;
  const Float floor = glm::clamp(v.floor, 0.f, 1.f);
  const Float w = (1.f - floor) / total, uniform = floor / static_cast<Float>(lights);
  Float acc = 0.f;
  for (uint32_t i = 0; i < lights; ++i) {
    site->light_pmf[i] = c[i] * w + uniform;
    acc += site->light_pmf[i];
    site->light_cdf[i] = acc;
  }
  site->light_cdf[lights - 1] = 1.f;  // the last light takes the rounding
  site->light_prob = kNeuralLightGuideProb;
}

// A light from the site's learned distribution (u in [0, 1)).
TESSERA_HOST_DEVICE inline uint32_t neural_sample_light(const NeuralGuideView& v, const NeuralSite& site, Float u) {
  uint32_t i = 0;
  while (i + 1 < v.lights && !(site.light_cdf[i] > u)) ++i;
  return i;
}

// G blocks of kLanes8 outputs (blocks[0..G), in increasing order) side by
// side: their sums are independent chains of additions (one block's chain
// alone waits on each addition's latency); finish(j, sum) takes each
// block's sum, block by block.
template <uint32_t G, class Finish>
TESSERA_LANES_FN void neural_output_blocks(const float* w3, const float* b3, uint32_t outs, uint32_t width, const Float* h2,
                                           const uint32_t* blocks, Finish& finish) {
  F8 acc[G];
  uint32_t j[G];
  for (uint32_t g = 0; g < G; ++g) {
    j[g] = blocks[g] * kLanes8;
    acc[g] = lanes_load(b3 + j[g]);
  }
  const float* col = w3;
  for (uint32_t i = 0; i < width; ++i, col += outs) {
    const F8 x = lanes_splat(h2[i]);
    for (uint32_t g = 0; g < G; ++g) acc[g] += lanes_load(col + j[g]) * x;
  }
  for (uint32_t g = 0; g < G; ++g) finish(j[g], acc[g]);
}

// Runs the network at a vertex (p on a surface whose normal on the path's
// side is n) and builds the site's distributions. Out of line on the GPU
// (device.h): large, and its work dwarfs a call's; the path loop's
// registers are then allocated without the network's.
TESSERA_HOST_DEVICE TESSERA_DEVICE_NOINLINE inline void neural_infer(const NeuralGuideView& v, const Vec3& p, const Vec3& n,
                                                                     NeuralSite* site) {
  const NeuralLayout L{v.width, v.table_log2, v.lights};
  Float in[kNeuralInputs], h1[kNeuralMaxWidth];
  Float* h2 = site->h2;
  neural_encode(v, p, n, in);
  neural_hidden_layer(v.params + L.w1(), v.params + L.b1(), in, kNeuralInputs, v.width, h1);
  neural_hidden_layer(v.params + L.w2(), v.params + L.b2(), h1, v.width, v.width, h2);
  site->p = p;
  site->n = n;
  site->has_cdf = false;
  // The output layer, exp, Q x max(cos, 0), its sum and the largest Q above
  // the surface in one pass over the tiles of 8 bins, each tile a block in
  // registers (lanes8.h; each bin's sums in a fixed order). A tile whose
  // bins all lie below the surface adds exactly 0 to the sums and the
  // maximum, and gives each of its bins the floor's share: it is skipped (a
  // bin's Q there is computed from h2 when read, neural_site_q: a bin the
  // floor or a transmission drew). Half the tiles are skipped on floors and
  // ceilings of a y-up scene, a third on walls facing x, 4 of 18 facing z.
  static_assert(kNeuralTile == kLanes8, "a tile is a block of lanes");
  static_assert(kNeuralTiles <= 32, "a bit per tile");
  constexpr uint32_t kBlocks = kNeuralTiles;
  const uint32_t outs = L.outputs(), width = v.width;
  const float* w3 = v.params + L.w3();
  const float* b3 = v.params + L.b3();
  Float* q = site->q;
  Float* pmf = site->weight;
  const Float* dx = v.bin_dir_soa;
  const Float* dy = dx + kNeuralBins;
  const Float* dz = dy + kNeuralBins;
  const Float nx = n.x, ny = n.y, nz = n.z;
  const F8 scale = lanes_splat(v.scale), zero = lanes_splat(0.f);
  // max(cos, 0) per bin into the weights (Q x it overwrites them), and the blocks to compute.
  uint32_t active[kBlocks], count = 0, skipped = 0;
  for (uint32_t b = 0; b < kBlocks; ++b) {
    const uint32_t j = b * kLanes8;
    const F8 c = lanes_load(dx + j) * nx + lanes_load(dy + j) * ny + lanes_load(dz + j) * nz;
    const F8 cosine = lanes_select_gt(c, zero, c, zero);
    lanes_store(pmf + j, cosine);
    const bool above = lanes_any_gt(cosine, zero);
    active[count] = b;
    count += above ? 1u : 0u;
    skipped |= above ? 0u : 1u << b;
  }
  site->skipped = skipped;
  F8 lane_sum = zero, lane_max = zero;
  auto finish = [&](uint32_t j, F8 acc) {
    const F8 qj = scale * neural_exp8(acc);
    const F8 cosine = lanes_load(pmf + j);
    const F8 above = lanes_select_gt(cosine, zero, qj, zero);  // Q of the bins above the surface, 0 below
    const F8 weighted = qj * cosine;
    lanes_store(q + j, qj);
    lanes_store(pmf + j, weighted);
    lane_sum += weighted;
    lane_max = lanes_select_gt(lane_max, above, lane_max, above);
  };
  // Six blocks at a time, the rest in groups of three, two and one. Blocks
  // in increasing order: the sums' order is the bins'.
  uint32_t a = 0;
  for (; a + 6 <= count; a += 6) neural_output_blocks<6>(w3, b3, outs, width, h2, active + a, finish);
  if (a + 3 <= count) {
    neural_output_blocks<3>(w3, b3, outs, width, h2, active + a, finish);
    a += 3;
  }
  if (a + 2 <= count) {
    neural_output_blocks<2>(w3, b3, outs, width, h2, active + a, finish);
    a += 2;
  }
  if (a < count) neural_output_blocks<1>(w3, b3, outs, width, h2, active + a, finish);
  // The light outputs (raw: neural_light_distribution takes their exp),
  // eight at a time: one hidden unit's light weights are contiguous in w3.
  // Lanes past the last light read the next unit's first weights (the last
  // unit's, at most 7 of the outs biases that follow) and are not kept;
  // each kept lane's sum is the scalar one, in the same order.
  for (uint32_t o = kNeuralBins; o < outs; o += kLanes8) {
    F8 acc = zero;
    for (uint32_t k = 0; k < kLanes8 && o + k < outs; ++k) acc[k] = b3[o + k];
    const float* col = w3 + o;
    for (uint32_t i = 0; i < width; ++i, col += outs) acc += lanes_load(col) * lanes_splat(h2[i]);
    for (uint32_t k = 0; k < kLanes8 && o + k < outs; ++k) q[o + k] = acc[k];
  }
  Float total = 0.f, qmax = 0.f;
  for (uint32_t k = 0; k < kLanes8; ++k) {
    total += lane_sum[k];
    qmax = glm::max(qmax, lane_max[k]);
  }
  site->irradiance = total * (4.f * kPi / static_cast<Float>(kNeuralBins));
  site->qmax = qmax;
  const Float floor = glm::clamp(v.floor, 0.f, 1.f);
  const Float uniform = total > 0.f ? floor / static_cast<Float>(kNeuralBins) : 1.f / static_cast<Float>(kNeuralBins);
  const Float w = total > 0.f ? (1.f - floor) / total : 0.f;
  site->pmf_scale = w;
  site->pmf_floor = uniform;
  neural_light_distribution(v, site);
}

// Bin j's probability in the site's guided distribution (floor included).
TESSERA_HOST_DEVICE inline Float neural_site_pmf(const NeuralSite& site, uint32_t j) {
  return site.weight[j] * site.pmf_scale + site.pmf_floor;
}

// The site's cdf over tiles of bins, built once per vertex by the first
// sample that needs it. Sampling takes two levels (a tile, then a bin in
// it): the tiles' sums are independent chains of additions, where one
// running sum over the 144 bins is a single long one.
TESSERA_HOST_DEVICE inline void neural_build_cdf(NeuralSite* site) {
  Float tile[kNeuralTiles] = {};
  for (uint32_t k = 0; k < kNeuralTile; ++k)
    for (uint32_t t = 0; t < kNeuralTiles; ++t) tile[t] += neural_site_pmf(*site, t * kNeuralTile + k);
  Float acc = 0.f;
  for (uint32_t t = 0; t < kNeuralTiles; ++t) {
    acc += tile[t];
    site->tile_cdf[t] = acc;
  }
  // The last tile takes the rounding: u < 1 always finds a tile.
  site->tile_cdf[kNeuralTiles - 1] = 1.f;
  site->has_cdf = true;
}

// Bin j's Q from the last hidden layer h2: one output, the operations of
// neural_infer's block of 8 bins in the same order (the same bits).
TESSERA_HOST_DEVICE inline Float neural_bin_q(const NeuralGuideView& v, const Float* h2, uint32_t j) {
  const NeuralLayout L{v.width, v.table_log2, v.lights};
  const uint32_t outs = L.outputs();
  const float* w3 = v.params + L.w3();
  Float acc = v.params[L.b3() + j];
  for (uint32_t i = 0; i < v.width; ++i) acc += w3[static_cast<size_t>(i) * outs + j] * h2[i];
  return v.scale * neural_exp(acc);
}

// One value of the network at a point, computed alone: the irradiance
// (y_bin == kNeuralIrradiance) or one bin's Q (y_bin < kNeuralBins; 0 for
// anything else), the same bits as neural_infer's site->irradiance and
// site->q[y_bin]. A bin's Q needs one output, not 144, and the irradiance
// the blocks above the surface only, without the site's distributions: the
// bootstrapped parts of training targets are refreshed with it.
TESSERA_HOST_DEVICE inline Float neural_value(const NeuralGuideView& v, const Vec3& p, const Vec3& n, uint32_t y_bin) {
  if (y_bin != kNeuralIrradiance && y_bin >= kNeuralBins) return 0.f;
  const NeuralLayout L{v.width, v.table_log2, v.lights};
  Float in[kNeuralInputs], h1[kNeuralMaxWidth], h2[kNeuralMaxWidth];
  neural_encode(v, p, n, in);
  neural_hidden_layer(v.params + L.w1(), v.params + L.b1(), in, kNeuralInputs, v.width, h1);
  neural_hidden_layer(v.params + L.w2(), v.params + L.b2(), h1, v.width, v.width, h2);
  const uint32_t outs = L.outputs(), width = v.width;
  const float* w3 = v.params + L.w3();
  const float* b3 = v.params + L.b3();
  if (y_bin != kNeuralIrradiance) return neural_bin_q(v, h2, y_bin);
  const Float* dx = v.bin_dir_soa;
  const Float* dy = dx + kNeuralBins;
  const Float* dz = dy + kNeuralBins;
  const F8 scale = lanes_splat(v.scale), zero = lanes_splat(0.f);
  F8 lane_sum = zero;
  for (uint32_t j = 0; j < kNeuralBins; j += kLanes8) {
    const F8 c = lanes_load(dx + j) * n.x + lanes_load(dy + j) * n.y + lanes_load(dz + j) * n.z;
    const F8 cosine = lanes_select_gt(c, zero, c, zero);
    if (!lanes_any_gt(cosine, zero)) continue;  // adds exactly 0 in neural_infer
    F8 acc = lanes_load(b3 + j);
    const float* col = w3 + j;
    for (uint32_t i = 0; i < width; ++i, col += outs) acc += lanes_load(col) * lanes_splat(h2[i]);
    lane_sum += (scale * neural_exp8(acc)) * cosine;
  }
  Float total = 0.f;
  for (uint32_t k = 0; k < kLanes8; ++k) total += lane_sum[k];
  return total * (4.f * kPi / static_cast<Float>(kNeuralBins));
}

// Output j at the site as neural_infer gives it (a bin's Q, or a learned
// light's contribution); where neural_infer skipped the bin's block, from
// the last hidden layer the site keeps.
TESSERA_HOST_DEVICE inline Float neural_site_q(const NeuralGuideView& v, const NeuralSite& site, uint32_t j) {
  if (j >= kNeuralBins || !((site.skipped >> (j / kLanes8)) & 1u)) return site.q[j];
  return neural_bin_q(v, site.h2, j);
}

#if !TESSERA_IS_GPU_CODE
// neural_infer for the CPU, compiled for AVX2 where the processor has it
// (guidecache/neural/neural_infer_cpu.cpp; bit-identical either way).
void neural_infer_cpu(const NeuralGuideView& v, const Vec3& p, const Vec3& n, NeuralSite* site);
// Its two copies, for the test that they agree bit for bit.
void neural_infer_avx2(const NeuralGuideView& v, const Vec3& p, const Vec3& n, NeuralSite* site);
void neural_infer_portable(const NeuralGuideView& v, const Vec3& p, const Vec3& n, NeuralSite* site);
bool neural_infer_has_avx2();
// neural_value, compiled the same two ways.
Float neural_value_cpu(const NeuralGuideView& v, const Vec3& p, const Vec3& n, uint32_t y_bin);
#endif

TESSERA_HOST_DEVICE inline uint32_t neural_bin_of(const Vec3& dir) {
  const Vec2 uv = equal_area_sphere_to_square(dir);
  auto index = [](Float x) {
    const Float last = static_cast<Float>(kNeuralGrid - 1);
    return x > 0.f ? static_cast<uint32_t>(glm::min(x * static_cast<Float>(kNeuralGrid), last)) : 0u;
  };
  return neural_bin_at(index(uv.y), index(uv.x));
}

TESSERA_HOST_DEVICE inline Float neural_bin_pdf(const NeuralSite& site, uint32_t bin) {
  return neural_site_pmf(site, bin) * (static_cast<Float>(kNeuralBins) * kInv4Pi);
}

// Draws a bin from the site's cdf (u_bin) and a direction uniformly within it (u).
TESSERA_HOST_DEVICE inline bool neural_sample(NeuralSite& site, Float u_bin, Vec2 u, Vec3* dir, Float* pdf,
                                              uint32_t* bin_out) {
  if (!site.has_cdf) neural_build_cdf(&site);
  uint32_t tile = 0;  // the first tile whose cdf exceeds u_bin
  while (tile + 1 < kNeuralTiles && !(site.tile_cdf[tile] > u_bin)) ++tile;
  // Then the bin where the running sum within the tile passes what is left
  // of u_bin (the tile's last bin takes the rounding).
  const Float t = u_bin - (tile > 0 ? site.tile_cdf[tile - 1] : 0.f);
  const uint32_t first = tile * kNeuralTile;
  uint32_t k = 0;
  Float acc = neural_site_pmf(site, first);
  while (k + 1 < kNeuralTile && !(acc > t)) acc += neural_site_pmf(site, first + ++k);
  const uint32_t bin = first + k;
  if (!(neural_site_pmf(site, bin) > 0.f)) return false;
  const Float inv_grid = 1.f / static_cast<Float>(kNeuralGrid);
  *dir = equal_area_square_to_sphere(Vec2((static_cast<Float>(neural_bin_col(bin)) + u.x) * inv_grid,
                                          (static_cast<Float>(neural_bin_row(bin)) + u.y) * inv_grid));
  *pdf = neural_bin_pdf(site, bin);
  *bin_out = bin;
  return true;
}

// The bootstrapped part of a target, as NeuralTrainingSample keeps it:
// coef x the value (y_bin: kNeuralIrradiance or a bin) predicted at site y.
struct NeuralBootstrap {
  const NeuralSite* y = nullptr;  // null: nothing bootstrapped
  uint32_t y_bin = 0;
  Float coef = 0.f;
  Float value = 0.f;
};

// A path starts: its targets are numbered from 0, and the keep hash
// follows its pixel (index in the image) and sample index, not the order
// in which a thread or a device reaches it.
TESSERA_HOST_DEVICE inline void neural_sink_start_path(NeuralSampleSink* sink, uint64_t pixel_index, uint32_t sample_index) {
  uint64_t k = (pixel_index + 1) * 0x9E3779B97F4A7C15ull ^ (uint64_t{sample_index} * 0xC2B2AE3D27D4EB4Full);
  k ^= k >> 31;
  k *= 0xBF58476D1CE4E5B9ull;
  k ^= k >> 29;
  sink->path = static_cast<uint32_t>(k);
  sink->seen = 0;
  sink->path_kept = 0;
}

// Records a learning target for the site's bin into the calling thread's
// sink. Returns false (and counts it) when the target is rejected. Out of
// line on the GPU (learning only).
TESSERA_HOST_DEVICE TESSERA_DEVICE_NOINLINE inline bool neural_record(const NeuralGuideView& v, const NeuralSite& site,
                                                                      uint32_t bin, Float target,
                                                                      const NeuralBootstrap& boot = NeuralBootstrap{}) {
  NeuralSampleSink* sink = v.sink;
  if (!sink) return false;
  if (!(target >= 0.f) || !(target <= 3.4e38f)) {
    ++sink->rejected_nonfinite;
    return false;
  }
  if (target > v.max_target) {
    ++sink->rejected_large;
    return false;
  }
  // A hash of (tile, path, number in path) in [0, 1): which targets are kept.
  uint32_t h = sink->tile * 0x9E3779B1u ^ (sink->seen++ * 0x85EBCA77u) ^ sink->path;
  h ^= h >> 15;
  h *= 0x2C1B3C6Du;
  h ^= h >> 12;
  if (static_cast<Float>(h >> 8) * (1.f / 16777216.f) >= sink->keep_prob) return true;
  if (sink->path_kept >= kNeuralPathTargets || sink->count >= sink->capacity) {
    ++sink->dropped;
    return true;
  }
  ++sink->path_kept;
  NeuralTrainingSample& s = sink->data[sink->count++];
  for (int k = 0; k < 3; ++k) {
    s.p[k] = site.p[k];
    s.n[k] = site.n[k];
  }
  s.bin = bin;
  s.target = target;
  // A bootstrap whose coefficient or value is not a finite non-negative
  // number is not refreshed: the target stays as recorded.
  const bool refreshable = boot.y && boot.coef > 0.f && boot.coef <= 3.4e38f && boot.value >= 0.f &&
                           boot.value <= 3.4e38f && boot.coef * boot.value <= target * 1.001f;
  for (int k = 0; k < 3; ++k) {
    s.y_p[k] = refreshable ? boot.y->p[k] : 0.f;
    s.y_n[k] = refreshable ? boot.y->n[k] : 0.f;
  }
  s.y_bin = refreshable ? boot.y_bin : 0u;
  s.coef = refreshable ? boot.coef : 0.f;
  s.value = refreshable ? boot.value : 0.f;
  return true;
}

}  // namespace tessera
