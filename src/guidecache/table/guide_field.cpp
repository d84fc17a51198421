#include "guidecache/table/guide_field.h"

#include "guidecache/guide_kinds.h"
#include "guidecache/neural/neural_guide.h"
#include "kernels/effects.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace tessera {
namespace {

constexpr uint32_t kMaxGrid = 64;
constexpr Float kNormalSamples = 256.f;
constexpr uint32_t kMixMinVisits = 128;  // vertices a cell needs before its mixture weight is chosen

}  // namespace

GuideField::GuideField(const GuideConfig& config, const Vec3& bounds_lo, const Vec3& bounds_hi, uint32_t num_lights,
                       Float radiance_scale)
    : config_(config) {
  if (config_.grid < 2 || config_.grid > kMaxGrid) throw std::invalid_argument("guide: direction grid must be 2..64");
  bins_ = config_.grid * config_.grid;
  lights_ = (num_lights >= 3 && num_lights <= config_.max_learned_lights) ? num_lights : 0;
  // A cube around the scene, padded so points on its faces fall inside.
  Vec3 size = bounds_hi - bounds_lo;
  Float e = std::max({size.x, size.y, size.z, 1e-6f});
  Vec3 centre = 0.5f * (bounds_lo + bounds_hi);
  extent_ = e * 1.02f;
  lo_ = centre - Vec3(0.5f * extent_);
  // Fixed point: the brightest emitter maps to 2^24 units (targets well below
  // it keep ~7 significant digits); a single target may be 2^20 times brighter,
  // so ~2^19 of those still fit in a 64-bit sum.
  if (!(radiance_scale > 0.f) || !std::isfinite(radiance_scale)) radiance_scale = 1.f;
  fixed_scale_ = 16777216.f / radiance_scale;
  max_target_ = 1048576.f * radiance_scale;

  nodes_.resize(kGuideNormalClasses);
  node_depth_.assign(kGuideNormalClasses, 0);
  for (uint32_t c = 0; c < kGuideNormalClasses; ++c) nodes_[c].cell = static_cast<int32_t>(add_cell());
  // Seed each root's normal with its class axis until real normals arrive.
  for (uint32_t c = 0; c < kGuideNormalClasses; ++c)
    normal_sum_[3 * c + c / 2] = (c % 2 == 0 ? 1 : -1) * static_cast<int64_t>(kGuideNormalScale);
  build_bin_dirs();
  build_distributions();
  resize_accumulators();
}

size_t GuideField::add_cell() {
  size_t cell = cell_updates_.size();
  value_.resize(value_.size() + stride(), 0.f);
  visits_.resize(visits_.size() + stride(), 0u);
  normal_sum_.resize(normal_sum_.size() + 3, 0);
  cell_updates_.push_back(0);
  return cell;
}

uint64_t GuideField::bytes_per_cell() const {
  const uint64_t entry = sizeof(Float) + sizeof(uint32_t) + 2 * sizeof(uint64_t);  // value, visits, acc sum + count
  const uint64_t tables = bins_ * sizeof(GuideAlias) + (lights_ + 1) * sizeof(Float);  // alias table, light cdf
  // normal sum + its accumulator, update count, irradiance, qmax, light share, nee probability, mixture weight,
  // learn-normal flag
  const uint64_t extras = 3 * sizeof(int64_t) + 3 * sizeof(uint64_t) + sizeof(uint64_t) + 5 * sizeof(Float) + 1;
  const uint64_t node = (8 * sizeof(GuideNode) + 8) / 7 + 1;  // amortised share of the octree
  return stride() * entry + tables + extras + node;
}

uint64_t GuideField::split_threshold() const {
  return config_.split_updates > 0 ? config_.split_updates : 24ull * bins_;
}

void GuideField::resize_accumulators() { acc_.assign(acc_rejected_offset() + 3, 0); }

void GuideField::build_bin_dirs() {
  bin_dirs_.resize(bins_);
  for (uint32_t b = 0; b < bins_; ++b) {
    Vec2 sq((static_cast<Float>(b % config_.grid) + 0.5f) / config_.grid,
            (static_cast<Float>(b / config_.grid) + 0.5f) / config_.grid);
    bin_dirs_[b] = glm::normalize(equal_area_square_to_sphere(sq));
  }
}

uint32_t GuideField::spec_bits() const { return kSpecGuiding; }

void GuideField::views(GuideViews* out) {
  *out = GuideViews{};
  out->table = view();
}

void GuideField::fill_stats(GuideStats* out) const {
  *out = GuideStats{};
  out->table = stats();
}

bool GuideField::same_as(const Guide& other) const {
  const GuideField* o = dynamic_cast<const GuideField*>(&other);
  return o && *this == *o;
}

GuideView GuideField::view() {
  GuideView g;
  g.nodes = nodes_.data();
  g.num_nodes = static_cast<uint32_t>(nodes_.size());
  g.num_cells = num_cells();
  g.top_nodes = top_nodes_.data();
  g.lo = lo_;
  g.extent = extent_;
  g.grid = config_.grid;
  g.bins = bins_;
  g.lights = lights_;
  g.stride = stride();
  g.bin_dirs = bin_dirs_.data();
  g.value = value_.data();
  g.dir_alias = dir_alias_.data();
  g.light_cdf = light_cdf_.data();
  g.irradiance = irradiance_.data();
  g.qmax = qmax_.data();
  g.learn_normal = learn_normal_.data();
  g.cell_light_prob = cell_light_prob_.data();
  g.nee_prob = nee_prob_.data();
  g.nee_entry = nee_entry();
  g.mix_entry = mix_entry();
  g.cell_mix = cell_mix_.data();
  g.learn_mix = config_.learn_mix;
  g.acc = acc_.data();
  g.acc_normal = acc_.data() + acc_normal_offset();
  g.rejected = acc_.data() + acc_rejected_offset();
  g.acc_words = acc_.size();
  g.fixed_scale = fixed_scale_;
  g.max_target = max_target_;
  g.guide_prob = config_.guide_prob;
  g.target = config_.target;
  return g;
}

int32_t GuideField::find_cell(const Vec3& p, const Vec3& n) const {
  return guide_find_cell(const_cast<GuideField*>(this)->view(), p, n);
}

void GuideField::fold() {
  const size_t n = value_.size();
  const uint64_t* acc = acc_.data();
  const uint64_t* normal = acc_.data() + acc_normal_offset();
  const uint64_t* rejected = acc_.data() + acc_rejected_offset();
  const double inv_scale = 1.0 / fixed_scale_;
  for (size_t i = 0; i < n; ++i) {
    const uint64_t count = acc[2 * i + 1];
    if (count == 0) continue;
    // Running mean: the same result as `count` updates with alpha = 1/(1+visits).
    const double v = visits_[i], c = static_cast<double>(count);
    const double sum = static_cast<double>(acc[2 * i]) * inv_scale;
    value_[i] = static_cast<Float>((static_cast<double>(value_[i]) * v + sum) / (v + c));
    visits_[i] = static_cast<uint32_t>(std::min<uint64_t>(uint64_t(visits_[i]) + count, UINT32_MAX));
    totals_.updates += count;
    if (i % stride() < bins_) cell_updates_[i / stride()] += count;
  }
  for (size_t i = 0; i < normal_sum_.size(); ++i) normal_sum_[i] += static_cast<int64_t>(normal[i]);
  totals_.rejected_nonfinite += rejected[0];
  totals_.rejected_large += rejected[1];
  totals_.mix_out_of_range += rejected[2];

  // Refine busy leaves, in node order (deterministic), while the budget allows.
  const size_t leaves_before = nodes_.size();
  for (size_t i = 0; i < leaves_before; ++i) {
    const GuideNode& node = nodes_[i];
    if (node.child >= 0 || node_depth_[i] >= config_.max_depth) continue;
    if (cell_updates_[static_cast<size_t>(node.cell)] < split_threshold()) continue;
    if ((num_cells() + 7) * bytes_per_cell() > config_.budget_bytes) {
      totals_.budget_reached = true;
      break;
    }
    split(i);
  }
  build_distributions();
  resize_accumulators();
}

// The 8 children start from the parent's values (a good prior) with an
// eighth of its visits each (their expected share of the parent's samples),
// so they keep learning at a rate that matches what they have seen.
void GuideField::split(size_t node_index) {
  const int32_t parent_cell = nodes_[node_index].cell;
  const int32_t first_child = static_cast<int32_t>(nodes_.size());
  const uint8_t depth = static_cast<uint8_t>(node_depth_[node_index] + 1);
  for (int k = 0; k < 8; ++k) {
    size_t cell = k == 0 ? static_cast<size_t>(parent_cell) : add_cell();
    nodes_.push_back(GuideNode{-1, static_cast<int32_t>(cell)});
    node_depth_.push_back(depth);
  }
  const size_t s = stride(), p = static_cast<size_t>(parent_cell) * s;
  for (size_t e = 0; e < s; ++e) visits_[p + e] /= 8;
  for (int k = 1; k < 8; ++k) {
    const size_t c = static_cast<size_t>(nodes_[first_child + k].cell);
    std::copy_n(value_.begin() + p, s, value_.begin() + c * s);
    std::copy_n(visits_.begin() + p, s, visits_.begin() + c * s);
    std::copy_n(normal_sum_.begin() + 3 * parent_cell, 3, normal_sum_.begin() + 3 * c);
  }
  cell_updates_[static_cast<size_t>(parent_cell)] = 0;
  nodes_[node_index] = GuideNode{first_child, -1};
  ++totals_.splits;
}

// For every cube of the top grid, the node that covers it: descend from the
// root towards the cube's centre until depth kGuideTopLevels or a leaf.
void GuideField::build_top_nodes() {
  top_nodes_.resize(size_t(kGuideNormalClasses) * kGuideTopCells);
  const Float cube = extent_ / static_cast<Float>(kGuideTopSide);
  for (uint32_t c = 0; c < kGuideNormalClasses; ++c)
    for (uint32_t i = 0; i < kGuideTopCells; ++i) {
      const Vec3 grid(static_cast<Float>(i % kGuideTopSide), static_cast<Float>(i / kGuideTopSide % kGuideTopSide),
                      static_cast<Float>(i / (kGuideTopSide * kGuideTopSide)));
      const Vec3 centre = lo_ + (grid + 0.5f) * cube;
      int32_t node = static_cast<int32_t>(c);
      Vec3 lo = lo_;
      Float size = extent_;
      for (uint32_t level = 0; level < kGuideTopLevels && nodes_[node].child >= 0; ++level)
        node = nodes_[node].child + static_cast<int32_t>(guide_octant_step(centre, &lo, &size));
      top_nodes_[c * kGuideTopCells + i] = node;
    }
}

// Per cell: directions proportional to Q max(cos, 0) about the cell's mean
// normal (the product with a diffuse BSDF), lights proportional to their
// learned contribution; each mixed with a uniform floor. An untrained cell
// (all zero) samples uniformly, and its vertices draw no guided directions.
void GuideField::build_distributions() {
  build_top_nodes();
  const size_t cells = num_cells(), s = stride();
  dir_alias_.assign(cells * bins_, GuideAlias{});
  light_cdf_.assign(cells * (lights_ + 1), 0.f);
  irradiance_.assign(cells, 0.f);
  qmax_.assign(cells, 0.f);
  learn_normal_.assign(cells, 0);
  cell_light_prob_.assign(cells, 0.f);
  nee_prob_.assign(cells, 1.f);
  cell_mix_.assign(cells, config_.guide_prob);
  std::vector<double> w(std::max(bins_, lights_));
  const double floor = std::clamp<double>(config_.floor, 0.0, 1.0);
  // Probability of entry j of m: its weight's share, mixed with the uniform floor.
  auto mixed = [&](uint32_t j, uint32_t m, double total) {
    return total > 0.0 ? (1.0 - floor) * w[j] / total + floor / m : 1.0 / m;
  };
  // Vose's alias method over w[0..bins) (deterministic: fixed scan order).
  std::vector<double> scaled(bins_);
  std::vector<uint32_t> small, large;
  auto build_alias = [&](double total, GuideAlias* table) {
    const uint32_t m = bins_;
    small.clear();
    large.clear();
    for (uint32_t j = 0; j < m; ++j) {
      const double p = mixed(j, m, total);
      table[j].pmf = static_cast<Float>(p);
      scaled[j] = p * m;
      (scaled[j] < 1.0 ? small : large).push_back(j);
    }
    while (!small.empty() && !large.empty()) {
      const uint32_t s = small.back(), l = large.back();
      small.pop_back();
      table[s].keep = static_cast<Float>(scaled[s]);
      table[s].alias = l;
      scaled[l] -= 1.0 - scaled[s];
      if (scaled[l] < 1.0) {
        large.pop_back();
        small.push_back(l);
      }
    }
    // Leftovers are 1 up to rounding: keep themselves.
    for (uint32_t j : small) table[j].keep = 1.f, table[j].alias = j;
    for (uint32_t j : large) table[j].keep = 1.f, table[j].alias = j;
    for (uint32_t j = 0; j < m; ++j) table[j].alias_pmf = table[table[j].alias].pmf;
  };
  auto build_cdf = [&](uint32_t m, double total, Float* cdf) {
    double acc = 0.0;
    cdf[0] = 0.f;
    for (uint32_t j = 0; j < m; ++j) {
      acc += mixed(j, m, total);
      cdf[j + 1] = static_cast<Float>(acc);
    }
    cdf[m] = 1.f;
  };
  for (size_t c = 0; c < cells; ++c) {
    const Float* q = &value_[c * s];
    Vec3 n(static_cast<Float>(normal_sum_[3 * c]), static_cast<Float>(normal_sum_[3 * c + 1]),
           static_cast<Float>(normal_sum_[3 * c + 2]));
    Float len = glm::length(n);
    n = len > 0.f ? n / len : Vec3(0.f, 0.f, 1.f);
    // A few hundred normals fix a cell's orientation; later ones only cost atomics.
    learn_normal_[c] = len < kNormalSamples * kGuideNormalScale ? 1 : 0;
    double total = 0.0, qmax = 0.0;
    for (uint32_t j = 0; j < bins_; ++j) {
      double cosine = std::max(0.f, glm::dot(bin_dirs_[j], n));
      w[j] = static_cast<double>(q[j]) * cosine;
      total += w[j];
      if (cosine > 0.0) qmax = std::max(qmax, static_cast<double>(q[j]));
    }
    irradiance_[c] = static_cast<Float>(total * 4.0 * M_PI / bins_);
    qmax_[c] = static_cast<Float>(qmax);
    build_alias(total, &dir_alias_[c * bins_]);
    if (lights_ > 0) {
      double lt = 0.0;
      for (uint32_t j = 0; j < lights_; ++j) lt += (w[j] = q[bins_ + j]);
      build_cdf(lights_, lt, &light_cdf_[c * (lights_ + 1)]);
      // Until a cell has seen light, its table is uniform: selection by power does better.
      cell_light_prob_[c] = lt > 0.0 ? config_.light_guide_prob : 0.f;
    }
    nee_prob_[c] = nee_probability(c);
    cell_mix_[c] = mix_weight(c);
  }
}

// Next-event estimation pays a shadow ray at every vertex; where those rays
// bring a small share of the light a cell reflects (direct D against the
// learned indirect I, means over the same vertices), the cell traces them
// with probability nee_gain * D / (D + I), never below nee_min_prob: a share
// of a quarter or more (gain 4) keeps every shadow ray. Until a cell has
// seen kNeeMinVisits vertices (or reflects nothing), it keeps them all.
// Rarely-visible light is already in D as its mean, so a cell whose vertices
// sometimes see a bright light keeps a high probability.
Float GuideField::nee_probability(size_t cell) const {
  constexpr uint32_t kNeeMinVisits = 64;
  if (!(config_.nee_gain > 0.f)) return 1.f;
  const size_t e = cell * stride() + nee_entry();
  if (visits_[e] < kNeeMinVisits || visits_[e + 1] < kNeeMinVisits) return 1.f;
  const double d = value_[e], i = value_[e + 1];
  if (!(d + i > 0.0)) return 1.f;
  const double p = config_.nee_gain * d / (d + i);
  return static_cast<Float>(std::clamp(p, static_cast<double>(std::clamp(config_.nee_min_prob, 0.01f, 1.f)), 1.0));
}

// The candidate weight with the smallest mean second moment, once every
// candidate has kMixMinVisits vertices (-1 until then, or when the weight is
// fixed). The statistics are estimates from the field's own learning
// targets, so a field that is wrong where it is confident (a cell averaging
// points that see a light and points that do not) shows it here as the
// second moment of its higher weights.
int32_t GuideField::learned_mix_candidate(size_t cell) const {
  if (!config_.learn_mix) return -1;
  const size_t e = cell * stride() + mix_entry();
  uint32_t best = 0;
  for (uint32_t k = 0; k < kGuideMixEntries; ++k) {
    if (visits_[e + k] < kMixMinVisits) return -1;
    if (value_[e + k] < value_[e + best]) best = k;
  }
  return static_cast<int32_t>(best);
}

Float GuideField::mix_weight(size_t cell) const {
  const int32_t k = learned_mix_candidate(cell);
  return k >= 0 ? guide_mix_candidate(static_cast<uint32_t>(k)) : config_.guide_prob;
}

void GuideField::set_guide_prob(Float p) {
  config_.guide_prob = p;
  config_.learn_mix = false;
  for (size_t c = 0; c < cell_mix_.size(); ++c) cell_mix_[c] = mix_weight(c);
}

void GuideField::set_nee_gain(Float gain) {
  config_.nee_gain = gain;
  for (size_t c = 0; c < nee_prob_.size(); ++c) nee_prob_[c] = nee_probability(c);
}

GuideFieldStats GuideField::stats() const {
  GuideFieldStats s = totals_;
  s.cells = num_cells();
  s.bytes = num_cells() * bytes_per_cell();
  s.learned_nee = config_.nee_gain > 0.f;
  double mix_sum = 0.0;
  uint64_t guiding = 0;
  for (size_t c = 0; c < cell_mix_.size(); ++c) {
    if (!(irradiance_[c] > 0.f)) continue;
    mix_sum += cell_mix_[c];
    ++guiding;
    if (learned_mix_candidate(c) >= 0) ++s.mix_learned_cells;
  }
  s.mean_mix = guiding ? mix_sum / double(guiding) : 0.0;
  return s;
}

bool GuideField::operator==(const GuideField& o) const {
  return config_ == o.config_ && lo_ == o.lo_ && extent_ == o.extent_ && bins_ == o.bins_ && lights_ == o.lights_ &&
         fixed_scale_ == o.fixed_scale_ && max_target_ == o.max_target_ && value_ == o.value_ &&
         visits_ == o.visits_ && normal_sum_ == o.normal_sum_ && cell_updates_ == o.cell_updates_ &&
         node_depth_ == o.node_depth_ &&
         std::equal(nodes_.begin(), nodes_.end(), o.nodes_.begin(), o.nodes_.end(),
                    [](const GuideNode& a, const GuideNode& b) { return a.child == b.child && a.cell == b.cell; });
}

}  // namespace tessera
