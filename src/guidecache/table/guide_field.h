// The learned guide cache (host side): owns the flat arrays behind a
// GuideView, folds a pass's accumulators into the field, refines cells where
// they are visited often (within a memory budget), and serialises.
//
// Learning rule: each entry's value is the running mean of the targets it
// received, i.e. Q <- Q + alpha (target - Q) with alpha = 1 / (1 + visits)
// (Dahm & Keller 2017). Folding a pass's (sum, count) at once gives exactly
// the same mean as applying its targets one by one, in any order.
//
// Everything a fold decides (values, splits) is a function of the field and
// the summed accumulators only, so every process that folds the same sums
// keeps an identical field. No MPI here: a farm sums accumulators() across
// ranks and then calls fold().
#pragma once

#include <cstdint>
#include <iosfwd>
#include <string>
#include <vector>

#include "guidecache/guide.h"
#include "guidecache/table/guide_view.h"

namespace tessera {

struct GuideConfig {
  uint32_t grid = 12;                   // 12 x 12 = 144 direction bins, as in Dahm & Keller
  // Cells stop splitting when the next split would exceed it. Every guided
  // vertex reads the field at random: measured at equal time on the shipped
  // scenes, 4 MB beat 16 MB on four of five (the cache misses cost more than
  // the finer cells gain) and lost 3 % on the fifth.
  uint64_t budget_bytes = 4ull << 20;
  uint64_t split_updates = 0;           // a leaf splits after this many updates; 0 = 24 per bin
  uint32_t max_depth = 20;              // octree levels below a root
  Float guide_prob = 0.5f;
  // Learned light selection's share against power-based selection (in cells
  // that have learned some light). On shelter (6 lights) 0.9 gave 24 % lower
  // error than 0.5 at equal samples; the power-based tenth and the floor keep
  // every light possible.
  Float light_guide_prob = 0.9f;
  // Share of each distribution spread uniformly: no impossible bin. 2 % gave
  // 2-4 % lower error than 5 % on every shipped scene at equal samples, 10 % was worse.
  Float floor = 0.02f;
  GuideTarget target = GuideTarget::ExpectedSarsa;
  uint32_t max_learned_lights = 256;    // more lights than this: light selection stays power-based
  // Learned next-event probability (see GuideView::nee_prob): a cell whose
  // shadow rays bring less than 1/nee_gain of the light it reflects traces
  // them less often, down to nee_min_prob. nee_gain 0: always trace them.
  Float nee_gain = 4.f;
  Float nee_min_prob = 0.1f;
  // Learn the mixture weight per cell (from guide_prob, among
  // guide_mix_candidate()); off: guide_prob everywhere (--guide-mix given).
  bool learn_mix = true;

  bool operator==(const GuideConfig&) const = default;
};

struct GuideFieldStats {
  uint64_t cells = 0;
  uint64_t bytes = 0;
  uint64_t updates = 0;              // targets folded in, all passes
  uint64_t rejected_nonfinite = 0;   // NaN/Inf/negative targets
  uint64_t rejected_large = 0;       // targets beyond the fixed-point range
  uint64_t splits = 0;
  bool budget_reached = false;       // a split was refused for memory
  bool learned_nee = false;          // next-event probability learned per cell (config nee_gain > 0)
  uint64_t mix_out_of_range = 0;     // mixture statistics too large to record (a heuristic's input, not the image)
  uint64_t mix_learned_cells = 0;    // cells whose mixture weight was learned
  double mean_mix = 0.0;             // mean mixture weight over cells that guide
};

class GuideField final : public Guide {
 public:
  GuideField() = default;
  // bounds_lo/hi: the scene's bounds; num_lights: learned light selection is
  // on when 3 <= num_lights <= config.max_learned_lights (a single quad light is
  // two triangles: nothing to choose between); radiance_scale: the
  // brightest emitted radiance (sets the fixed-point range of targets).
  GuideField(const GuideConfig& config, const Vec3& bounds_lo, const Vec3& bounds_hi, uint32_t num_lights,
             Float radiance_scale);

  // Valid until the next fold(), load or destruction. Accumulators are
  // writable through it.
  GuideView view();

  // Folds accumulated targets into the values, refines busy cells, rebuilds
  // the sampling distributions and clears the accumulators.
  void fold();

  // The pass's accumulators, laid out as one array for reduction across
  // processes: (sum, count) pairs, normals, rejections (all 64-bit integers, summed).
  std::vector<uint64_t>& accumulators() { return acc_; }

  const GuideConfig& config() const { return config_; }

  // The Guide seam: one round, the accumulators, then fold().
  std::string mode() const override { return config_.target == GuideTarget::QLearning ? "qlearning" : "qtable"; }
  uint32_t spec_bits() const override;
  void views(GuideViews* out) override;
  uint32_t rounds() const override { return 1; }
  std::vector<uint64_t>& round_accumulators(uint32_t) override { return acc_; }
  void fold_round(uint32_t) override { fold(); }
  void fill_stats(GuideStats* out) const override;
  bool same_as(const Guide& other) const override;

  // Sampling settings that do not change what was learned.
  // A fixed mixture weight everywhere (learning the weight stops).
  void set_guide_prob(Float p) override;
  void set_nee_gain(Float gain);  // 0: every vertex traces its next-event shadow ray
  GuideFieldStats stats() const;
  uint32_t num_cells() const { return static_cast<uint32_t>(cell_updates_.size()); }
  uint32_t learned_lights() const { return lights_; }
  // The leaf cell for a point (host-side convenience over view()).
  int32_t find_cell(const Vec3& p, const Vec3& n) const;
  const Float* cell_values(int32_t cell) const { return &value_[static_cast<size_t>(cell) * stride()]; }

  // Versioned binary serialisation (cereal), with a checksum (guide_file.h).
  // scene_fingerprint ties a cache to the scene it was learned on; load()
  // throws std::runtime_error (one line) when the stream is not a guide
  // cache, has another version, is truncated or damaged (its checksum), has
  // another fingerprint, or holds a field no learning could have made: a
  // value that is negative or not finite, a probability outside [0, 1],
  // counts and octrees that disagree.
  void save(std::ostream& out, uint64_t scene_fingerprint) const override;
  static GuideField load(std::istream& in, uint64_t scene_fingerprint);

  bool operator==(const GuideField& o) const;

  template <class Archive>
  void serialize(Archive& ar);

 private:
  // Entries per cell: direction bins, learned lights, the next-event
  // statistics (kGuideNeeEntries), then the mixture statistics (kGuideMixEntries).
  uint32_t stride() const { return mix_entry() + kGuideMixEntries; }
  uint32_t nee_entry() const { return bins_ + lights_; }
  uint32_t mix_entry() const { return nee_entry() + kGuideNeeEntries; }
  uint64_t bytes_per_cell() const;
  uint64_t split_threshold() const;
  size_t add_cell();
  void split(size_t node);
  void build_distributions();
  Float nee_probability(size_t cell) const;
  int32_t learned_mix_candidate(size_t cell) const;
  Float mix_weight(size_t cell) const;
  void build_bin_dirs();
  void build_top_nodes();
  // Offsets of the parts of acc_.
  size_t acc_normal_offset() const { return 2 * num_cells() * size_t(stride()); }
  size_t acc_rejected_offset() const { return acc_normal_offset() + 3 * size_t(num_cells()); }
  void resize_accumulators();
  // What makes a loaded field unusable, "" if nothing (guide_io.cpp): its
  // settings, its octrees and array sizes, its values, and (once built) its
  // sampling distributions.
  std::string settings_problem() const;
  std::string tree_problem() const;
  std::string values_problem() const;
  std::string distributions_problem() const;

  GuideConfig config_;
  Vec3 lo_{0.f};
  Float extent_ = 1.f;
  uint32_t bins_ = 0, lights_ = 0;
  Float fixed_scale_ = 1.f, max_target_ = 1.f;

  std::vector<GuideNode> nodes_;
  std::vector<uint8_t> node_depth_;
  std::vector<Float> value_;           // cells * stride
  std::vector<uint32_t> visits_;       // cells * stride (saturating)
  std::vector<int64_t> normal_sum_;    // cells * 3, fixed point
  std::vector<uint64_t> cell_updates_; // direction updates since the cell was made
  GuideFieldStats totals_;

  // Derived (rebuilt by build_distributions, not serialised).
  std::vector<Vec3> bin_dirs_;
  std::vector<int32_t> top_nodes_;     // GuideView::top_nodes
  std::vector<Float> light_cdf_, irradiance_, qmax_;
  std::vector<GuideAlias> dir_alias_;
  std::vector<uint8_t> learn_normal_;
  std::vector<Float> cell_light_prob_, nee_prob_, cell_mix_;
  std::vector<uint64_t> acc_;
};

}  // namespace tessera
