// The neural guide (host side): owns the network's parameters and Adam's
// moments, collects a pass's learning targets, and trains between passes.
//
// What it learns is what the Q-table learns: per direction bin, the radiance
// arriving at a point (expected-SARSA targets, recorded by the integrator
// with the network frozen during the pass; each training step recomputes a
// target's bootstrapped part with the network as it is then). The loss is
// relative L2, (Q - T)^2 / (Q^2 + eps) with Q held constant in the
// denominator (Müller et al. 2021), whose minimiser is the mean target, as
// the table's running mean; its gradient is clipped, which bounds what a
// firefly target moves.
//
// Data-parallel and deterministic: after a pass, round 0 sums target
// statistics (the first one sets the output scale); each of the next
// `steps_per_pass` rounds sums the gradient of one minibatch (every
// steps_per_pass-th target of each tile), computed tile by tile and
// quantised to 64-bit fixed point (the hidden layers per tile, the entries
// a target reaches outside them per target), so that the integer sum is the
// same whichever rank (or thread) rendered which tile. Every rank then applies
// the same Adam step to the same sums: weights stay equal everywhere, and a
// farm's image equals a single process's bit for bit.
#pragma once

#include <cstdint>
#include <iosfwd>
#include <memory>
#include <vector>

#include "guidecache/guide.h"
#include "guidecache/neural/neural_training_log.h"

namespace tessera {

struct NeuralGuideConfig {
  // Neurons per hidden layer (two layers), at most kNeuralMaxWidth. Wider
  // lowers the error per sample where the light is intricate (shelter) but
  // not at equal time: the output layer (width x (144 + learned lights)) is
  // most of an inference's arithmetic (docs/neural-guide.md).
  uint32_t width = 8;
  // Adam steps (gradient reductions) after each learning pass, each on
  // its share of the pass's targets. Many small steps at a high rate are
  // what lets the network follow what the table learns at once; with
  // tile_targets, of the settings measured the one with the lowest error
  // at equal time (docs/neural-guide.md).
  uint32_t steps_per_pass = 48;
  Float learning_rate = 2e-2f;
  // Mixture weight of guided sampling once trained, until a learning pass
  // has chosen one of kNeuralMixCandidates (learn_mix; off with --guide-mix).
  Float guide_prob = 0.5f;
  bool learn_mix = true;
  Float floor = 0.02f;               // uniform share of each distribution (as the table's)
  // Learning targets a tile keeps per learning pass, on average (the rest
  // are skipped). More lower the error per sample, and training time grows
  // with them: twice as many, with 64 steps, were worse at equal time
  // (docs/neural-guide.md).
  uint32_t tile_targets = 256;
  // Entries per hash-grid level: 2^table_log2, in [kNeuralMinTableLog2,
  // kNeuralMaxTableLog2]. A larger table did not lower the error; 12 is the
  // largest whose parameters and Adam's moments stay under 1 MB.
  uint32_t table_log2 = 11;
  uint64_t seed = 1;                 // weight initialisation
  // How far from a pixel's earlier first vertex a later sample's may lie
  // and reuse its site (NeuralFirstSite, guidecache/path_guide.h), in cells of
  // the hash grid's finest level (0: only at the same point). Behaviour,
  // not learned state: not saved (a loaded guide, a farm worker's and a
  // resumed one have the default; only code sets another).
  Float reuse_cells = 2.f;
  bool operator==(const NeuralGuideConfig&) const = default;
};

// Relative L2's denominator floor, in units of the output scale squared.
// Below sqrt(eps) a bin's gradient fades: a large floor leaves dark bins
// too bright, which flattens the distribution (docs/neural-guide.md).
constexpr float kNeuralLossEps = 1e-6f;

struct NeuralGuideStats {
  uint64_t params = 0;
  uint64_t bytes = 0;                // parameters and Adam's two moments
  uint64_t steps = 0;                // optimiser steps taken
  uint64_t targets = 0;              // learning targets trained on (all passes, all ranks)
  uint64_t rejected_nonfinite = 0;   // NaN/Inf/negative targets
  uint64_t rejected_large = 0;       // targets beyond max_target
  uint64_t dropped = 0;              // kept targets beyond a tile's buffer
  uint64_t gradient_clamped = 0;     // fixed-point gradient words saturated (hidden layers per tile, others per target)
  uint64_t nonfinite_gradients = 0;  // targets whose gradient had a NaN or Inf (left out of their step)
  double loss = 0.0;                 // mean loss of the last pass's minibatches
  std::vector<double> pass_loss;     // the same, per learning pass
  double train_seconds = 0.0;        // this process: gradients and steps
  double inference_seconds = 0.0;    // one inference, as last measured on this process
  Float mix_weight = 0.f;            // the mixture weight the next pass samples with
  uint64_t mix_vertices = 0;         // vertices that gave mixture statistics (all passes, all ranks)
  uint64_t mix_rejected = 0;         // vertices whose statistics were NaN or overflowed (left out)
};

class NeuralGuide final : public Guide {
 public:
  NeuralGuide() = default;
  NeuralGuide(const NeuralGuide&) = delete;  // it owns the pass's training log
  NeuralGuide& operator=(const NeuralGuide&) = delete;
  // bounds_lo/hi: the scene's bounds (the encoded cube); radiance_scale: the
  // brightest emitted radiance (sets which targets are rejected as too large);
  // num_lights: the scene's lights (light selection is learned for
  // kNeuralMinLights..kNeuralMaxLights of them).
  NeuralGuide(const NeuralGuideConfig& config, const Vec3& bounds_lo, const Vec3& bounds_hi, Float radiance_scale,
              uint32_t num_lights = 0);

  std::string mode() const override { return "neural"; }
  uint32_t spec_bits() const override;
  void views(GuideViews* out) override;
  NeuralTrainingLog* training_log() override { return &log_; }
  uint32_t rounds() const override;
  uint32_t max_rounds() const override { return 1 + config_.steps_per_pass; }
  std::vector<uint64_t>& round_accumulators(uint32_t round) override;
  void fold_round(uint32_t round) override;
  bool single_sample_learning_passes() const override { return true; }
  // A fixed mixture weight: no longer learned.
  void set_guide_prob(Float p) override {
    config_.guide_prob = p;
    config_.learn_mix = false;
  }
  // The mixture weight the next pass samples with: the candidate the last
  // learning pass's statistics chose (NeuralSampleSink::mix_moments), else guide_prob.
  Float mix_weight() const;
  // Its index among the table's candidates (guide_mix_candidate; -1: none chosen yet).
  int32_t mix_candidate() const { return mix_candidate_; }
  void save(std::ostream& out, uint64_t scene_fingerprint) const override;
  void fill_stats(GuideStats* out) const override;
  bool same_as(const Guide& other) const override;

  static std::unique_ptr<NeuralGuide> load(std::istream& in, uint64_t scene_fingerprint);

  const NeuralGuideConfig& config() const { return config_; }
  uint32_t learned_lights() const { return lights_; }
  // The lights a network made for a scene of num_lights learns selection over.
  static uint32_t learned_lights_for(uint32_t num_lights) {
    return num_lights >= kNeuralMinLights && num_lights <= kNeuralMaxLights ? num_lights : 0u;
  }
  NeuralLayout layout() const { return NeuralLayout{config_.width, config_.table_log2, lights_}; }
  const std::vector<float>& params() const { return params_; }
  NeuralGuideView view() const;
  NeuralGuideStats stats() const;
  bool operator==(const NeuralGuide& o) const;

  // Training on given targets, for tests and the library's own use: the
  // same rounds a pass runs, on one process.
  void train_on(std::vector<NeuralTileTargets> tiles);
  // Loss (mean over the targets) and its gradient (sums over the targets,
  // then divided by their count) for one tile's targets: what a round
  // computes, exposed for the gradient check.
  double loss_and_gradient(const std::vector<NeuralTrainingSample>& samples, std::vector<float>* grad) const;
  std::vector<float>& mutable_params() { return params_; }
  Float output_scale() const { return scale_; }
  void set_output_scale(Float s) { scale_ = s; }

  template <class Archive>
  void serialize(Archive& ar);
  template <class Archive>
  void read_fields(Archive& ar, uint32_t version, uint64_t scene_fingerprint);

 private:
  void init_params();
  void build_bin_dirs();
  // Where tile_gradient puts a tile's gradient (defined in neural_guide.cpp).
  struct GradientSink;
  // Adds the loss gradient of the given targets of one tile (every
  // `stride`-th from `first`) to *sink; returns the loss sum over the
  // targets used (*count of them; a target whose gradient has a NaN or Inf
  // adds nothing and is counted in *nonfinite).
  double tile_gradient(const std::vector<NeuralTrainingSample>& samples, uint32_t first, uint32_t stride,
                       GradientSink* sink, uint64_t* count, uint64_t* nonfinite) const;
  void adam_step(uint64_t count);

  NeuralGuideConfig config_;
  uint32_t lights_ = 0;               // learned lights (NeuralLayout::lights)
  Vec3 lo_{0.f};
  Float extent_ = 1.f;
  Float radiance_scale_ = 1.f;
  Float max_target_ = 1.f;
  Float scale_ = 0.f;                 // output scale: 0 until the first targets set it
  std::vector<float> params_, adam_m_, adam_v_;
  uint64_t steps_ = 0;
  // The candidate mixture weight the last learning pass chose, as an index of
  // guide_mix_candidate (kNeuralMixFirstCandidate on; -1: none yet).
  int32_t mix_candidate_ = -1;
  NeuralGuideStats totals_;

  // Derived and per pass (not serialised).
  std::vector<Vec3> bin_dirs_;
  std::vector<Float> bin_dir_soa_;
  NeuralTrainingLog log_;
  std::vector<NeuralTileTargets> pass_tiles_;
  NeuralLogCounts pass_counts_;
  uint64_t pass_targets_ = 0;         // summed over ranks (round 0)
  double pass_loss_sum_ = 0.0;
  uint64_t pass_loss_count_ = 0;
  std::vector<uint64_t> acc_;
  // Each training thread's gradient buffers, kept from round to round (a
  // round used to allocate and add up P-sized buffers per thread; with small
  // minibatches that was most of a step). Defined in neural_guide.cpp.
  struct TrainScratch;
  std::shared_ptr<TrainScratch> scratch_;
  std::vector<double> adam_grad_;  // adam_step's converted gradients
};

}  // namespace tessera
