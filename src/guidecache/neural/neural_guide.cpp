#include "guidecache/neural/neural_guide.h"

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <chrono>
#include <cmath>
#include <cstring>
#include <stdexcept>

#include "guidecache/guide_kinds.h"
#include "guidecache/table/guide_field.h"
#include "kernels/effects.h"

namespace tessera {

namespace {

// Fixed point of gradient sums (per tile): 2^-24 resolution; a word beyond
// kGradLimit (2^44, a gradient sum of 2^20) saturates there (counted), so
// that 2^19 - 1 saturated tiles still sum within int64.
constexpr double kGradScale = 16777216.0;
constexpr double kGradLimit = 17592186044416.0;
// The hash-grid and output-layer words are quantised per target
// (GradientSink): one saturates at 2^40 (a gradient of 2^16, counted), so
// that 2^23 - 1 saturated targets at one entry still sum within int64.
constexpr double kWordLimit = 1099511627776.0;
constexpr double kLossScale = 1048576.0;
constexpr double kLossLimit = 1e6;                 // per target, for the loss statistic only
// |dL/d output| per target: a bound on what one firefly target moves, loose
// enough that rare bright targets (light through a gap, a light seen from
// few points) still pull their means up (docs/neural-guide.md).
constexpr float kGradClip = 100.f;
constexpr double kAdamBeta1 = 0.9, kAdamBeta2 = 0.99, kAdamEps = 1e-10;
// Target statistics of round 0: fixed point with unit radiance_scale * 2^-20.
constexpr double kTargetUnit = 1.0 / 1048576.0;
// Vertices a learning pass's mixture statistics need before they choose the
// weight (a single-sample pass of a 256x192 image gives about 10^5).
constexpr uint64_t kNeuralMixMinVertices = 1024;

uint64_t splitmix(uint64_t* state) {
  uint64_t z = (*state += 0x9E3779B97F4A7C15ull);
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  return z ^ (z >> 31);
}
float uniform_pm(uint64_t* state, float a) {  // uniform in [-a, a)
  return a * (2.f * static_cast<float>(splitmix(state) >> 40) * (1.f / 16777216.f) - 1.f);
}

uint64_t to_word(int64_t v) { return static_cast<uint64_t>(v); }
int64_t from_word(uint64_t w) { return static_cast<int64_t>(w); }

// The nearest integer (ties to even) of |x| <= 2^51, from the bits of
// x + 1.5 * 2^52: plain arithmetic, so a loop of it runs on vector lanes
// (a conversion of double to int64 has no SSE2 or AVX2 form).
inline int64_t to_fixed(double x) {
  const double shifted = x + 6755399441055744.0;
  int64_t bits;
  std::memcpy(&bits, &shifted, sizeof bits);
  return bits - 0x4338000000000000ll;
}

}  // namespace

// A training thread's sums: the fixed-point gradient (P words; zero outside
// the dense hidden-layer block and `dirty`), the float gradient of the
// hidden layers of the tile it is on (zero between tiles), and the round's
// statistics.
struct NeuralGuide::TrainScratch {
  struct Local {
    std::vector<int64_t> sum;
    std::vector<float> grad;
    std::vector<uint32_t> dirty;  // entries of `sum` outside the dense block made non-zero this round
    uint64_t loss = 0, count = 0, clamped = 0, nonfinite = 0;
  };
  tbb::enumerable_thread_specific<Local> locals;
};

// Where one tile's gradient goes. The hidden layers' block (dense: every
// target reaches all of it) is summed in floats over the tile and quantised
// once per tile by the round. The hash-grid and output-layer entries a
// target reaches (137 of 34 296 at the default sizes) are quantised per
// target into `words`, the training thread's fixed-point sums, `dirty`
// listing the words it made non-zero: integer sums, which do not depend on
// which thread added which target, without a second pass over a list of
// the tile's entries. Without words (loss_and_gradient, the gradient check)
// they are summed in `dense` as floats.
struct NeuralGuide::GradientSink {
  float* dense = nullptr;
  int64_t* words = nullptr;
  std::vector<uint32_t>* dirty = nullptr;
  uint64_t clamped = 0;
  void add(uint32_t k, float g) {
    if (!words) {
      dense[k] += g;
      return;
    }
    double x = static_cast<double>(g) * kGradScale;  // finite: tile_gradient checked the target
    if (!(std::fabs(x) <= kWordLimit)) {
      ++clamped;
      x = x > 0.0 ? kWordLimit : -kWordLimit;
    }
    const int64_t q = to_fixed(x);
    if (q == 0) return;
    if (words[k] == 0) dirty->push_back(k);
    words[k] += q;
  }
};

NeuralGuide::NeuralGuide(const NeuralGuideConfig& config, const Vec3& lo, const Vec3& hi, Float radiance_scale,
                         uint32_t num_lights)
    : config_(config),
      lights_(learned_lights_for(num_lights)) {
  if (config_.width < 1 || config_.width > kNeuralMaxWidth)
    throw std::runtime_error("neural guide: width must be 1.." + std::to_string(kNeuralMaxWidth));
  if (config_.steps_per_pass < 1) throw std::runtime_error("neural guide: at least one step per pass");
  if (config_.table_log2 < kNeuralMinTableLog2 || config_.table_log2 > kNeuralMaxTableLog2)
    throw std::runtime_error("neural guide: hash table of 2^" + std::to_string(config_.table_log2) + " entries (2^" +
                             std::to_string(kNeuralMinTableLog2) + " to 2^" + std::to_string(kNeuralMaxTableLog2) + ")");
  if (config_.tile_targets < 1 || config_.tile_targets > (1u << 20))
    throw std::runtime_error("neural guide: " + std::to_string(config_.tile_targets) + " targets per tile (1 to 2^20)");
  const Vec3 d = hi - lo;
  extent_ = std::max({d.x, d.y, d.z, 1e-6f}) * 1.001f;
  lo_ = lo - Vec3(extent_ * 0.0005f);
  radiance_scale_ = radiance_scale > 0.f && std::isfinite(radiance_scale) ? radiance_scale : 1.f;
  max_target_ = 1048576.f * radiance_scale_;
  init_params();
}

void NeuralGuide::init_params() {
  const NeuralLayout L = layout();
  params_.assign(L.size(), 0.f);
  adam_m_.assign(L.size(), 0.f);
  adam_v_.assign(L.size(), 0.f);
  uint64_t state = config_.seed;
  // Hash-grid features start near zero (instant-ngp); layers He-uniform for
  // ReLU, the output layer smaller, biases zero: outputs start near the scale.
  for (uint32_t i = L.grid(); i < L.w1(); ++i) params_[i] = uniform_pm(&state, 1e-4f);
  auto fill = [&](uint32_t from, uint32_t count, float a) {
    for (uint32_t i = 0; i < count; ++i) params_[from + i] = uniform_pm(&state, a);
  };
  const float w = static_cast<float>(config_.width);
  fill(L.w1(), kNeuralInputs * config_.width, std::sqrt(6.f / kNeuralInputs));
  fill(L.w2(), config_.width * config_.width, std::sqrt(6.f / w));
  fill(L.w3(), config_.width * L.outputs(), 0.1f * std::sqrt(6.f / w));
  build_bin_dirs();
}

void NeuralGuide::build_bin_dirs() {
  bin_dirs_.resize(kNeuralBins);
  for (uint32_t b = 0; b < kNeuralBins; ++b) {
    const Vec2 sq((static_cast<Float>(neural_bin_col(b)) + 0.5f) / kNeuralGrid,
                  (static_cast<Float>(neural_bin_row(b)) + 0.5f) / kNeuralGrid);  // the network's numbering
    bin_dirs_[b] = glm::normalize(equal_area_square_to_sphere(sq));
  }
  bin_dir_soa_.resize(3 * kNeuralBins);
  for (uint32_t b = 0; b < kNeuralBins; ++b)
    for (uint32_t k = 0; k < 3; ++k) bin_dir_soa_[k * kNeuralBins + b] = bin_dirs_[b][k];
}

uint32_t NeuralGuide::spec_bits() const { return kSpecGuiding | kSpecNeural; }

NeuralGuideView NeuralGuide::view() const {
  NeuralGuideView v;
  v.params = params_.data();
  v.width = config_.width;
  v.table_log2 = config_.table_log2;
  v.lights = lights_;
  v.lo = lo_;
  v.extent = extent_;
  v.reuse_radius = config_.reuse_cells * extent_ / static_cast<Float>(neural_level_resolution(kNeuralLevels - 1));
  v.scale = scale_ > 0.f ? scale_ : radiance_scale_;
  v.guide_prob = mix_weight();
  v.learn_mix = config_.learn_mix;
  v.floor = config_.floor;
  v.trained = steps_ > 0;
  v.max_target = max_target_;
  v.bin_dirs = bin_dirs_.data();
  v.bin_dir_soa = bin_dir_soa_.data();
  v.tile_targets = config_.tile_targets;
  return v;
}

void NeuralGuide::views(GuideViews* out) {
  *out = GuideViews{};
  out->neural = view();
}

uint32_t NeuralGuide::rounds() const { return 1 + (pass_targets_ > 0 ? config_.steps_per_pass : 0u); }

double NeuralGuide::tile_gradient(const std::vector<NeuralTrainingSample>& samples, uint32_t first, uint32_t stride,
                                  GradientSink* sink, uint64_t* count, uint64_t* nonfinite) const {
  const NeuralLayout L = layout();
  const uint32_t W = config_.width, O = L.outputs();
  const size_t n = samples.size();
  const size_t batch = n > first ? (n - first + stride - 1) / stride : 0;
  *count = 0;
  if (batch == 0) return 0.0;
  const NeuralGuideView v = view();
  const float scale = v.scale;
  const float* P = params_.data();
  const float *w1 = P + L.w1(), *b1 = P + L.b1(), *w2 = P + L.w2(), *b2 = P + L.b2(), *w3 = P + L.w3(),
              *b3 = P + L.b3();
  float* G = sink->dense;
  float *gw1 = G + L.w1(), *gb1 = G + L.b1(), *gw2 = G + L.w2(), *gb2 = G + L.b2();
  // One target at a time, forward and backward, every sum in a fixed order
  // (weights input-major: w[i * out + o]); the tile's gradient is the sum
  // over its targets in their order. Per-tile minibatches are a few targets
  // (256 per tile over 48 steps: 5), too small for a matrix library's
  // products to pay their packing (docs/neural-guide.md).
  Float x[kNeuralInputs], h1[kNeuralMaxWidth], h2[kNeuralMaxWidth], dh1[kNeuralMaxWidth], dh2[kNeuralMaxWidth];
  float dx[kNeuralEncoded];
  double loss = 0.0;
  uint64_t used = 0;
  for (size_t b = 0; b < batch; ++b) {
    const NeuralTrainingSample& s = samples[first + b * stride];
    // The target, its bootstrapped part recomputed by the network as it is
    // now (NeuralTrainingSample): what the next vertex is predicted to send
    // moves with every step, not only between passes. (Before the first step
    // the network is still the one that recorded it: nothing to redo.) A
    // refreshed target is kept within [0, max_target]: the recorded one was
    // checked against it, and only the network's new prediction is added.
    float t = s.target;
    if (s.coef > 0.f && v.trained) {
      const Float now = neural_value_cpu(v, Vec3(s.y_p[0], s.y_p[1], s.y_p[2]), Vec3(s.y_n[0], s.y_n[1], s.y_n[2]), s.y_bin);
      const float refreshed = s.target + s.coef * (now - s.value);
      if (std::isfinite(refreshed)) t = std::min(std::max(refreshed, 0.f), max_target_);
    }
    const Vec3 p(s.p[0], s.p[1], s.p[2]);
    neural_encode(v, p, Vec3(s.n[0], s.n[1], s.n[2]), x);
    neural_hidden_layer(w1, b1, x, kNeuralInputs, W, h1);
    neural_hidden_layer(w2, b2, h1, W, W, h2);
    const uint32_t bin = s.bin < O ? s.bin : 0u;  // a direction bin or a light
    float o = b3[bin];
    for (uint32_t i = 0; i < W; ++i) o += w3[static_cast<size_t>(i) * O + bin] * h2[i];
    const float q = neural_exp(o);
    const float ts = t / scale;
    const float denom = q * q + kNeuralLossEps;
    const double target_loss = std::min(static_cast<double>((q - ts) * (q - ts) / denom), kLossLimit);
    const float go = std::clamp(2.f * (q - ts) * q / denom, -kGradClip, kGradClip);
    // Back through the layers (weights input-major: a column of W^T is a
    // row of w), nothing added yet: ReLU units that were not positive pass nothing.
    for (uint32_t i = 0; i < W; ++i) dh2[i] = h2[i] > 0.f ? w3[static_cast<size_t>(i) * O + bin] * go : 0.f;
    for (uint32_t i = 0; i < W; ++i) {
      const float* row = w2 + static_cast<size_t>(i) * W;
      float acc = 0.f;
      for (uint32_t k = 0; k < W; ++k) acc += row[k] * dh2[k];
      dh1[i] = h1[i] > 0.f ? acc : 0.f;
    }
    for (uint32_t i = 0; i < kNeuralEncoded; ++i) {  // to the encoding only, not the normal
      const float* row = w1 + static_cast<size_t>(i) * W;
      float acc = 0.f;
      for (uint32_t k = 0; k < W; ++k) acc += row[k] * dh1[k];
      dx[i] = acc;
    }
    // A NaN or Inf in anything the gradient is made of (a NaN target that
    // got past the sinks, a NaN weight, an overflow) leaves this target out
    // (counted): x * 0 is 0 exactly when x is finite.
    float poison = go * 0.f + static_cast<float>(target_loss) * 0.f;
    for (uint32_t i = 0; i < kNeuralInputs; ++i) poison += x[i] * 0.f;
    for (uint32_t i = 0; i < W; ++i) poison += h1[i] * 0.f + h2[i] * 0.f + dh1[i] * 0.f + dh2[i] * 0.f;
    for (uint32_t i = 0; i < kNeuralEncoded; ++i) poison += dx[i] * 0.f;
    if (!(poison == 0.f)) {
      ++*nonfinite;
      continue;
    }
    loss += target_loss;
    ++used;
    // The output layer: only the trained output's entries.
    for (uint32_t i = 0; i < W; ++i) sink->add(L.w3() + i * O + bin, go * h2[i]);
    sink->add(L.b3() + bin, go);
    // The hidden layers (dense: d_out x in, and d_out for the bias).
    for (uint32_t i = 0; i < W; ++i) {
      float* row = gw2 + static_cast<size_t>(i) * W;
      for (uint32_t k = 0; k < W; ++k) row[k] += dh2[k] * h1[i];
    }
    for (uint32_t k = 0; k < W; ++k) gb2[k] += dh2[k];
    for (uint32_t i = 0; i < kNeuralInputs; ++i) {
      float* row = gw1 + static_cast<size_t>(i) * W;
      for (uint32_t k = 0; k < W; ++k) row[k] += dh1[k] * x[i];
    }
    for (uint32_t k = 0; k < W; ++k) gb1[k] += dh1[k];
    // The encoding's gradient, scattered to the corners of each level.
    U8 entry[8];
    F8 weight[8];
    neural_corners8(L.table_size(), neural_unit_position(v, p), entry, weight);
    for (uint32_t l = 0; l < kNeuralLevels; ++l) {
      const uint32_t level_base = L.grid() + l * L.table_size() * kNeuralFeatures;
      for (uint32_t c = 0; c < 8; ++c)
        for (uint32_t f = 0; f < kNeuralFeatures; ++f)
          sink->add(level_base + entry[c][l] * kNeuralFeatures + f, weight[c][l] * dx[l * kNeuralFeatures + f]);
    }
  }
  *count = used;
  return loss;
}

double NeuralGuide::loss_and_gradient(const std::vector<NeuralTrainingSample>& samples, std::vector<float>* grad) const {
  grad->assign(params_.size(), 0.f);
  GradientSink sink;
  sink.dense = grad->data();
  uint64_t count = 0, nonfinite = 0;
  const double loss = tile_gradient(samples, 0, 1, &sink, &count, &nonfinite);
  if (count == 0) return 0.0;
  for (float& g : *grad) g /= static_cast<float>(count);
  return loss / static_cast<double>(count);
}

std::vector<uint64_t>& NeuralGuide::round_accumulators(uint32_t round) {
  const auto t0 = std::chrono::steady_clock::now();
  if (round == 0) {
    pass_tiles_ = log_.take(&pass_counts_);
    pass_targets_ = 0;
    pass_loss_sum_ = 0.0;
    pass_loss_count_ = 0;
    uint64_t count = 0, sum = 0;
    for (const NeuralTileTargets& t : pass_tiles_) {
      count += t.samples.size();
      for (const NeuralTrainingSample& s : t.samples)  // (the sinks let no non-finite target in; train_on may)
        if (std::isfinite(s.target) && s.target >= 0.f && s.target <= max_target_)
          sum += static_cast<uint64_t>(static_cast<double>(s.target) / radiance_scale_ / kTargetUnit + 0.5);
    }
    acc_ = {count, sum, pass_counts_.rejected_nonfinite, pass_counts_.rejected_large, pass_counts_.dropped};
    acc_.insert(acc_.end(), pass_counts_.mix_moments, pass_counts_.mix_moments + kNeuralMixCandidates);
    acc_.push_back(pass_counts_.mix_vertices);
    acc_.push_back(pass_counts_.mix_rejected);
    return acc_;
  }
  // One minibatch: every steps_per_pass-th target of each tile, from round - 1.
  const size_t P = params_.size();
  const uint32_t first = round - 1, stride = config_.steps_per_pass;
  // A tile reaches the hidden layers (dense), the output layer's entries
  // of the outputs it trains and a few hash-grid entries: only those are
  // quantised and added up, not every parameter per tile.
  const size_t layers = layout().w1(), hidden_end = layout().w3();
  using Local = TrainScratch::Local;
  if (!scratch_) scratch_ = std::make_shared<TrainScratch>();
  // A round that throws (out of memory) leaves the buffers dirty: they go.
  struct DropOnThrow {
    std::shared_ptr<TrainScratch>& scratch;
    bool done = false;
    ~DropOnThrow() {
      if (!done) scratch.reset();
    }
  } drop_on_throw{scratch_};
  tbb::parallel_for(size_t(0), pass_tiles_.size(), [&](size_t i) {
    Local& local = scratch_->locals.local();
    if (local.sum.size() != P) {
      local.sum.assign(P, 0);
      local.grad.assign(P, 0.f);
    }
    GradientSink sink;
    sink.dense = local.grad.data();
    sink.words = local.sum.data();
    sink.dirty = &local.dirty;
    uint64_t count = 0;
    const double loss = tile_gradient(pass_tiles_[i].samples, first, stride, &sink, &count, &local.nonfinite);
    local.clamped += sink.clamped;
    // The hidden layers' block, summed over the tile's targets (each
    // finite): quantised once per tile, in a loop without branches (on
    // vector lanes). A sum that overflowed the floats (enormous weights)
    // saturates like any other beyond the limit (counted); one that became
    // NaN on the way (Inf - Inf) adds nothing (counted with them).
    float* grad = local.grad.data();
    int64_t* sum = local.sum.data();
    uint64_t clamped = 0;
    for (size_t k = layers; k < hidden_end; ++k) {
      double g = static_cast<double>(grad[k]) * kGradScale;
      clamped += !(std::fabs(g) <= kGradLimit);
      g = g == g ? g : 0.0;
      sum[k] += to_fixed(std::min(std::max(g, -kGradLimit), kGradLimit));
      grad[k] = 0.f;
    }
    local.clamped += clamped;
    if (count == 0) return;
    local.loss += static_cast<uint64_t>(std::llround(loss * kLossScale));
    local.count += count;
  });
  // Integer sums: the same whichever thread added which tile. Each thread's
  // buffers are left zero for the next round.
  acc_.assign(P + 4, 0);
  for (Local& local : scratch_->locals) {
    if (local.sum.empty()) continue;
    auto move = [&](size_t k) {
      acc_[k] += to_word(local.sum[k]);
      local.sum[k] = 0;
    };
    for (size_t k = layers; k < hidden_end; ++k) move(k);
    for (uint32_t k : local.dirty) move(k);
    local.dirty.clear();
    acc_[P] += local.loss;
    acc_[P + 1] += local.count;
    acc_[P + 2] += local.clamped;
    acc_[P + 3] += local.nonfinite;
    local.loss = local.count = local.clamped = local.nonfinite = 0;
  }
  drop_on_throw.done = true;
  totals_.train_seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return acc_;
}

// beta^steps by repeated multiplication, not pow(): libm's pow may differ in
// its last bit between machines (glibc picks an FMA variant where it can).
static double adam_power(double beta, uint64_t steps) {
  double p = 1.0;
  for (uint64_t i = 0; i < steps && p > 0.0; ++i) p *= beta;
  return p;
}

// The step from the summed fixed-point gradients (acc_[0..P), over `count`
// targets). Parameter by parameter, so threads change no result. The
// gradients are converted first (int64 to double has no SSE2 vector form),
// so that the update itself, a division and a square root per parameter,
// runs on vector lanes: it is every parameter's, every step.
void NeuralGuide::adam_step(uint64_t count) {
  ++steps_;
  const size_t P = params_.size();
  const double lr1 = config_.learning_rate / (1.0 - adam_power(kAdamBeta1, steps_));  // bias corrections folded in
  const double ic2 = 1.0 / (1.0 - adam_power(kAdamBeta2, steps_));
  const double unit = 1.0 / (kGradScale * static_cast<double>(count));
  adam_grad_.resize(P);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, P, 4096), [&](const tbb::blocked_range<size_t>& r) {
    double* grad = adam_grad_.data();
    for (size_t k = r.begin(); k < r.end(); ++k) grad[k] = static_cast<double>(from_word(acc_[k])) * unit;
    float* m = adam_m_.data();
    float* v = adam_v_.data();
    float* w = params_.data();
    for (size_t k = r.begin(); k < r.end(); ++k) {
      const double g = grad[k];
      const double mk = kAdamBeta1 * m[k] + (1.0 - kAdamBeta1) * g;
      const double vk = kAdamBeta2 * v[k] + (1.0 - kAdamBeta2) * g * g;
      m[k] = static_cast<float>(mk);
      v[k] = static_cast<float>(vk);
      w[k] = static_cast<float>(w[k] - lr1 * mk / (std::sqrt(vk * ic2) + kAdamEps));
    }
  });
}

void NeuralGuide::fold_round(uint32_t round) {
  const auto t0 = std::chrono::steady_clock::now();
  if (round == 0) {
    pass_targets_ = acc_[0];
    totals_.targets += acc_[0];
    totals_.rejected_nonfinite += acc_[2];
    totals_.rejected_large += acc_[3];
    totals_.dropped += acc_[4];
    totals_.mix_vertices += acc_[5 + kNeuralMixCandidates];
    totals_.mix_rejected += acc_[6 + kNeuralMixCandidates];
    // The mixture weight for the next passes: the candidate with the
    // smallest second moment over the pass's vertices (summed over ranks),
    // once enough vertices gave theirs.
    if (config_.learn_mix && acc_[5 + kNeuralMixCandidates] >= kNeuralMixMinVertices) {
      uint32_t best = 0;
      for (uint32_t k = 1; k < kNeuralMixCandidates; ++k)
        if (acc_[5 + k] < acc_[5 + best]) best = k;
      mix_candidate_ = static_cast<int32_t>(kNeuralMixFirstCandidate + best);
    }
    // The first targets set the output scale: their mean radiance (a
    // network that starts near 0 then predicts it, and learns in relative terms).
    if (!(scale_ > 0.f) && acc_[0] > 0) {
      const double mean = static_cast<double>(acc_[1]) * kTargetUnit * radiance_scale_ / static_cast<double>(acc_[0]);
      scale_ = static_cast<Float>(std::max(mean, 1e-6 * radiance_scale_));
    }
    // This process's cost of one inference, for the stats.
    if (!pass_tiles_.empty() && !pass_tiles_.front().samples.empty()) {
      const NeuralGuideView v = view();
      const std::vector<NeuralTrainingSample>& s = pass_tiles_.front().samples;
      const size_t n = std::min<size_t>(s.size(), 256);
      NeuralSite site;
      Float sink = 0.f;
      const auto i0 = std::chrono::steady_clock::now();
      for (size_t i = 0; i < n; ++i) {
        neural_infer_cpu(v, Vec3(s[i].p[0], s[i].p[1], s[i].p[2]), Vec3(s[i].n[0], s[i].n[1], s[i].n[2]), &site);
        sink += site.irradiance;
      }
      const double dt = std::chrono::duration<double>(std::chrono::steady_clock::now() - i0).count();
      if (sink >= 0.f || sink < 0.f) totals_.inference_seconds = dt / static_cast<double>(n);
    }
    if (pass_targets_ == 0) pass_tiles_.clear();
    return;
  }
  const size_t P = params_.size();
  const uint64_t count = acc_[P + 1];
  totals_.gradient_clamped += acc_[P + 2];
  totals_.nonfinite_gradients += acc_[P + 3];  // targets left out of this step
  if (count > 0) {
    adam_step(count);
    pass_loss_sum_ += static_cast<double>(acc_[P]) / kLossScale;
    pass_loss_count_ += count;
  }
  if (round == config_.steps_per_pass) {
    pass_tiles_.clear();
    if (pass_loss_count_ > 0) {
      totals_.loss = pass_loss_sum_ / static_cast<double>(pass_loss_count_);
      totals_.pass_loss.push_back(totals_.loss);
    }
  }
  totals_.train_seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

void NeuralGuide::train_on(std::vector<NeuralTileTargets> tiles) {
  for (NeuralTileTargets& t : tiles) {
    NeuralSampleSink sink;
    sink.tile = t.tile;
    sink.data = t.samples.data();
    sink.count = static_cast<uint32_t>(t.samples.size());
    log_.add_tile(sink);
  }
  for (uint32_t r = 0; r < rounds(); ++r) {
    round_accumulators(r);
    fold_round(r);
  }
}

Float NeuralGuide::mix_weight() const {
  if (!config_.learn_mix || mix_candidate_ < 0) return config_.guide_prob;
  return guide_mix_candidate(static_cast<uint32_t>(mix_candidate_));
}

NeuralGuideStats NeuralGuide::stats() const {
  NeuralGuideStats s = totals_;
  s.mix_weight = mix_weight();
  s.params = params_.size();
  s.bytes = 3 * params_.size() * sizeof(float);
  s.steps = steps_;
  return s;
}

void NeuralGuide::fill_stats(GuideStats* out) const {
  out->table = GuideFieldStats{};
  GuideFieldStats* table = &out->table;
  table->bytes = 3 * params_.size() * sizeof(float);
  table->updates = totals_.targets;
  table->rejected_nonfinite = totals_.rejected_nonfinite;
  table->rejected_large = totals_.rejected_large;
  out->neural = stats();
}

bool NeuralGuide::operator==(const NeuralGuide& o) const {
  return config_ == o.config_ && lights_ == o.lights_ && lo_ == o.lo_ && extent_ == o.extent_ && radiance_scale_ == o.radiance_scale_ &&
         scale_ == o.scale_ && params_ == o.params_ && adam_m_ == o.adam_m_ && adam_v_ == o.adam_v_ &&
         steps_ == o.steps_ && mix_candidate_ == o.mix_candidate_;
}

bool NeuralGuide::same_as(const Guide& other) const {
  const NeuralGuide* o = dynamic_cast<const NeuralGuide*>(&other);
  return o && *this == *o;
}

}  // namespace tessera
