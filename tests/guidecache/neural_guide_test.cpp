// The neural guide on its own: its gradient against finite differences,
// learning a known field, data-parallel training that does not depend on
// how the tiles are split, exact save/load, and rejected targets.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <cstring>
#include <sstream>
#include <stdexcept>

#include "guidecache/table/guide_field.h"
#include "guidecache/neural/neural_guide.h"
#include "guidecache/path_guides.h"

namespace tessera {
namespace {

// A saved network (version 6: the magic and cereal's endianness byte, the
// version, the payload's size and checksum, then the payload with its own
// endianness byte) rewritten as version 5, which had no checksum: raw damage
// then reaches the range checks behind it.
std::string as_version5(const std::string& file) {
  constexpr size_t kVersionAt = sizeof "tessera-neural-guide" + 1, kPayloadAt = kVersionAt + 4 + 8 + 8;
  uint32_t version = 0;
  std::memcpy(&version, file.data() + kVersionAt, 4);
  if (version != 6) throw std::logic_error("not the layout as_version5 knows");
  std::string v5 = file.substr(0, kVersionAt);
  version = 5;
  v5.append(reinterpret_cast<const char*>(&version), 4);
  return v5 + file.substr(kPayloadAt + 1);
}

NeuralGuideConfig small_config(uint32_t width = 8) {
  NeuralGuideConfig c;
  c.width = width;
  c.steps_per_pass = 8;
  c.learning_rate = 1e-2f;
  return c;
}

NeuralGuide make(const NeuralGuideConfig& c, uint32_t lights = 0) {
  return NeuralGuide(c, Vec3(0.f), Vec3(1.f), 1.f, lights);
}

std::vector<NeuralTrainingSample> random_samples(size_t n, uint32_t seed, float target_scale) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(0.f, 1.f);
  std::vector<NeuralTrainingSample> out(n);
  for (NeuralTrainingSample& s : out) {
    for (int k = 0; k < 3; ++k) s.p[k] = u(rng);
    s.n[0] = 0.f, s.n[1] = 0.f, s.n[2] = 1.f;
    s.bin = static_cast<uint32_t>(u(rng) * kNeuralBins) % kNeuralBins;
    s.target = target_scale * (0.5f + u(rng));
  }
  return out;
}

// One pass of 4 tiles of 256 random targets each, every target then
// reshaped by shape(its number in the tile, the target).
template <class Shape>
std::vector<NeuralTileTargets> training_pass(int pass, Shape shape) {
  std::vector<NeuralTileTargets> tiles(4);
  for (uint32_t t = 0; t < tiles.size(); ++t) {
    tiles[t].tile = t;
    tiles[t].samples = random_samples(256, 100 * pass + t, 1.f);
    for (size_t i = 0; i < tiles[t].samples.size(); ++i) shape(i, tiles[t].samples[i]);
  }
  return tiles;
}

// The network's Q for a sample's bin, through the kernels' inference.
double predicted(const NeuralGuide& g, const NeuralTrainingSample& s) {
  const NeuralGuideView v = g.view();
  NeuralSite site;
  neural_infer(v, Vec3(s.p[0], s.p[1], s.p[2]), Vec3(s.n[0], s.n[1], s.n[2]), &site);
  return neural_site_q(v, site, s.bin);
}

// The loss with its denominators frozen at q0 (what the gradient is of:
// relative L2 treats them as constants), in double.
double frozen_loss(const NeuralGuide& g, const std::vector<NeuralTrainingSample>& s, const std::vector<double>& q0) {
  double sum = 0.0;
  const double scale = g.output_scale();
  for (size_t i = 0; i < s.size(); ++i) {
    const double q = predicted(g, s[i]) / scale, t = s[i].target / scale, d = q0[i] * q0[i] + kNeuralLossEps;
    sum += (q - t) * (q - t) / d;
  }
  return sum / static_cast<double>(s.size());
}

// Hash features larger than the initial ones, so that their gradients are
// not all tiny.
void randomise_hash_features(NeuralGuide& g) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> u(-0.5f, 0.5f);
  const NeuralLayout L = g.layout();
  for (uint32_t i = L.grid(); i < L.w1(); ++i) g.mutable_params()[i] = u(rng);
}

TEST(NeuralGuide, GradientMatchesFiniteDifferences) {
  NeuralGuide g = make(small_config(), 4);  // with four light outputs
  ASSERT_EQ(g.learned_lights(), 4u);
  g.set_output_scale(1.f);
  randomise_hash_features(g);
  const NeuralLayout L = g.layout();
  // Targets near the predictions: the per-target gradient is not clipped.
  std::vector<NeuralTrainingSample> samples = random_samples(12, 5, 1.f);
  for (size_t i = 0; i < samples.size(); i += 3) samples[i].bin = kNeuralBins + static_cast<uint32_t>(i / 3) % 4;
  for (NeuralTrainingSample& s : samples) s.target = static_cast<float>(predicted(g, s) * (s.bin % 2 ? 1.6 : 0.5));
  std::vector<double> q0;
  for (const NeuralTrainingSample& s : samples) q0.push_back(predicted(g, s));
  std::vector<float> grad;
  g.loss_and_gradient(samples, &grad);
  // Parameters with a gradient worth checking: touched hash entries, and every layer.
  std::vector<uint32_t> check;
  for (uint32_t i = L.grid(); i < L.w1() && check.size() < 8; ++i)
    if (std::fabs(grad[i]) > 1e-3f) check.push_back(i);
  for (uint32_t block : {L.w1(), L.b1(), L.w2(), L.b2(), L.w3(), L.b3(), L.b3() + kNeuralBins}) {
    uint32_t found = 0;
    for (uint32_t i = block; i < L.size() && found < 4; ++i)
      if (std::fabs(grad[i]) > 1e-3f) check.push_back(i), ++found;
  }
  ASSERT_GE(check.size(), 20u);
  const double centre = frozen_loss(g, samples, q0);
  uint32_t compared = 0;
  for (uint32_t i : check) {
    const float keep = g.mutable_params()[i];
    const float h = 1e-2f * std::max(1.f, std::fabs(keep));
    g.mutable_params()[i] = keep + h;
    const double up = frozen_loss(g, samples, q0);
    g.mutable_params()[i] = keep - h;
    const double down = frozen_loss(g, samples, q0);
    g.mutable_params()[i] = keep;
    // A ReLU switching within +-h makes the one-sided slopes differ: no
    // derivative to compare there.
    const double right = (up - centre) / h, left = (centre - down) / h;
    if (std::fabs(right - left) > 0.05 * std::max(std::fabs(right), std::fabs(left)) + 1e-4) continue;
    const double fd = (up - down) / (2.0 * h);
    EXPECT_NEAR(grad[i], fd, 0.02 * std::fabs(fd) + 2e-4) << "parameter " << i;
    ++compared;
  }
  EXPECT_GE(compared, 16u);
}

// What a round adds up (the per-tile fixed point of the hidden layers, the
// per-target words of everything else) is the float gradient of
// loss_and_gradient, which the test above checks: every parameter's word
// within the rounding of its targets. A NaN target is left out alone.
TEST(NeuralGuide, RoundSumsAreTheGradientInFixedPoint) {
  NeuralGuideConfig c = small_config();
  c.steps_per_pass = 1;  // one minibatch: every target
  NeuralGuide g = make(c, 4);
  randomise_hash_features(g);
  std::vector<NeuralTrainingSample> samples = random_samples(40, 7, 1.f);
  for (size_t i = 0; i < samples.size(); i += 5) samples[i].bin = kNeuralBins + static_cast<uint32_t>(i / 5) % 4;
  const size_t n = samples.size(), P = g.params().size();
  auto round_sums = [&](NeuralGuide& guide, std::vector<NeuralTrainingSample>& s) {
    NeuralSampleSink sink;
    sink.data = s.data();
    sink.count = static_cast<uint32_t>(s.size());
    guide.training_log()->add_tile(sink);
    guide.round_accumulators(0);
    guide.fold_round(0);  // sets the output scale
    return guide.round_accumulators(1);
  };
  const std::vector<uint64_t> acc = round_sums(g, samples);
  ASSERT_EQ(acc.size(), P + 4);
  EXPECT_EQ(acc[P + 1], n);  // targets used
  EXPECT_EQ(acc[P + 3], 0u);
  std::vector<float> grad;
  g.loss_and_gradient(samples, &grad);  // the mean: times n below
  uint32_t nonzero = 0;
  for (size_t k = 0; k < P; ++k) {
    const double fixed = static_cast<double>(static_cast<int64_t>(acc[k])) / 16777216.0;
    const double exact = static_cast<double>(grad[k]) * static_cast<double>(n);
    ASSERT_NEAR(fixed, exact, static_cast<double>(n) / 16777216.0 + 1e-4 + 1e-5 * std::fabs(exact)) << "parameter " << k;
    nonzero += acc[k] != 0;
  }
  EXPECT_GT(nonzero, 1000u);  // the hidden layers, 40 targets' hash-grid and output entries

  NeuralGuide h = make(c, 4);
  h.mutable_params() = g.params();
  std::vector<NeuralTrainingSample> poisoned = samples;
  poisoned[7].target = std::nanf("");
  const std::vector<uint64_t> left = round_sums(h, poisoned);
  EXPECT_EQ(left[P + 1], n - 1);
  EXPECT_EQ(left[P + 3], 1u);
}

// One bright direction everywhere: radiance 1 from bin kBright, 0.01 from
// every other. After training, the network predicts the bright bin within
// 10 % at points it never saw, the others at 0.01 within 50 % on average
// and each below 0.05, and its guided distribution puts most of its mass
// there (above a +z surface: 0.7 here).
TEST(NeuralGuide, LearnsASingleBrightDirection) {
  constexpr uint32_t kBright = neural_bin_at(6, 5);  // a bin above a +z surface
  NeuralGuideConfig c = small_config(16);
  NeuralGuide g = make(c);
  const NeuralGuideView v0 = g.view();
  ASSERT_GT(glm::dot(v0.bin_dirs[kBright], Vec3(0.f, 0.f, 1.f)), 0.3f);
  for (int pass = 0; pass < 40; ++pass)
    g.train_on(training_pass(pass, [&](size_t i, NeuralTrainingSample& s) {
      if (i % 3 == 0) s.bin = kBright;  // a third of the samples took the bright direction
      s.target = s.bin == kBright ? 1.f : 0.01f;
    }));
  EXPECT_EQ(g.stats().steps, 40u * c.steps_per_pass);
  const NeuralGuideView v = g.view();
  std::mt19937 rng(99);
  std::uniform_real_distribution<float> u(0.f, 1.f);
  for (int i = 0; i < 20; ++i) {
    NeuralSite site;
    neural_infer(v, Vec3(u(rng), u(rng), u(rng)), Vec3(0.f, 0.f, 1.f), &site);
    double dark = 0.0;
    for (uint32_t j = 0; j < kNeuralBins; ++j) dark += j != kBright ? neural_site_q(v, site, j) : 0.f;
    EXPECT_NEAR(dark / (kNeuralBins - 1), 0.01, 0.005);
    EXPECT_NEAR(neural_site_q(v, site, kBright), 1.0, 0.1);
    for (uint32_t j = 0; j < kNeuralBins; j += 13) {
      if (j != kBright) {
        EXPECT_LT(neural_site_q(v, site, j), 0.05) << "bin " << j;
      }
    }
    EXPECT_GT(neural_site_pmf(site, kBright), 0.5f);
  }
}

// Bootstrapped targets are recomputed by the network as it trains: points
// with x < 0.5 see, through bin kBin, half of what the point x + 0.5 sees
// through it (1 there, known exactly). Their targets were recorded when the
// network predicted 8 there (the target 4, stale): they still learn 0.5.
TEST(NeuralGuide, BootstrappedTargetsFollowTheNetwork) {
  constexpr uint32_t kBin = 77;
  NeuralGuideConfig c = small_config(16);
  NeuralGuide g = make(c);
  for (int pass = 0; pass < 40; ++pass)
    g.train_on(training_pass(pass, [&](size_t, NeuralTrainingSample& s) {
      s.bin = kBin;
      if (s.p[0] >= 0.5f) {
        s.target = 1.f;
        return;
      }
      s.y_p[0] = s.p[0] + 0.5f, s.y_p[1] = s.p[1], s.y_p[2] = s.p[2];
      s.y_n[0] = 0.f, s.y_n[1] = 0.f, s.y_n[2] = 1.f;
      s.y_bin = kBin;
      s.coef = 0.5f;
      s.value = 8.f;
      s.target = s.coef * s.value;
    }));
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> u(0.05f, 0.45f);
  for (int i = 0; i < 20; ++i) {
    NeuralTrainingSample s{};
    s.p[0] = u(rng), s.p[1] = 2.f * u(rng), s.p[2] = 2.f * u(rng);
    s.n[2] = 1.f;
    s.bin = kBin;
    EXPECT_NEAR(predicted(g, s), 0.5, 0.1) << s.p[0] << " " << s.p[1] << " " << s.p[2];
  }
}

// Light outputs learn each light's contribution; the site's light
// distribution follows it (with the floor), is drawn from in proportion to
// its pmf, and is only used once the network has trained.
TEST(NeuralGuide, LearnsWhichLightContributes) {
  constexpr uint32_t kLights = 5, kBright = 3;
  NeuralGuideConfig c = small_config(16);
  NeuralGuide g = make(c, kLights);
  EXPECT_EQ(make(c, 2).learned_lights(), 0u);  // a single quad light: selection by power
  EXPECT_EQ(make(c, kNeuralMaxLights + 1).learned_lights(), 0u);
  {
    NeuralSite site;
    neural_infer(g.view(), Vec3(0.5f), Vec3(0.f, 0.f, 1.f), &site);
    EXPECT_EQ(site.light_prob, 0.f);  // untrained: power alone
  }
  for (int pass = 0; pass < 40; ++pass)
    g.train_on(training_pass(pass, [&](size_t i, NeuralTrainingSample& s) {
      if (i % 2 == 0) return;  // half direction targets, half light targets
      s.bin = kNeuralBins + static_cast<uint32_t>(i / 2) % kLights;
      s.target = s.bin == kNeuralBins + kBright ? 2.f : 0.02f;
    }));
  const NeuralGuideView v = g.view();
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u(0.f, 1.f);
  for (int i = 0; i < 10; ++i) {
    NeuralSite site;
    neural_infer(v, Vec3(u(rng), u(rng), u(rng)), Vec3(0.f, 0.f, 1.f), &site);
    EXPECT_EQ(site.light_prob, kNeuralLightGuideProb);
    EXPECT_NEAR(site.q[kNeuralBins + kBright], 2.0, 0.3);
    double sum = 0.0;
    for (uint32_t l = 0; l < kLights; ++l) {
      sum += site.light_pmf[l];
      EXPECT_GE(site.light_pmf[l], c.floor / kLights * 0.999f);
      if (l != kBright) {
        EXPECT_LT(site.q[kNeuralBins + l], 0.1) << "light " << l;
      }
    }
    EXPECT_NEAR(sum, 1.0, 1e-5);
    EXPECT_EQ(site.light_cdf[kLights - 1], 1.f);
    EXPECT_GT(site.light_pmf[kBright], 0.9f);
    // Draws follow the pmf (chi-square over the lights, 4 degrees of freedom: 18.5 is p = 0.001).
    std::vector<int> counts(kLights, 0);
    const int n = 20000;
    for (int k = 0; k < n; ++k) ++counts[neural_sample_light(v, site, (k + 0.5f) / n)];
    double chi2 = 0.0;
    for (uint32_t l = 0; l < kLights; ++l) {
      const double e = n * site.light_pmf[l];
      chi2 += (counts[l] - e) * (counts[l] - e) / e;
    }
    EXPECT_LT(chi2, 18.5);
  }
}

// Data parallelism: the tiles split over two "ranks", each computing its
// own rounds, their accumulators summed, every rank folding the sums, end
// with the same weights as one process training on all tiles: bit for bit.
TEST(NeuralGuide, TrainingDoesNotDependOnWhichRankHadWhichTile) {
  const NeuralGuideConfig c = small_config();
  NeuralGuide one = make(c), a = make(c), b = make(c);
  for (int pass = 0; pass < 3; ++pass) {
    std::vector<NeuralTileTargets> tiles(6);
    for (uint32_t t = 0; t < tiles.size(); ++t) tiles[t] = {t, random_samples(50 + 7 * t, 10 * pass + t, 0.3f)};
    auto feed = [](NeuralGuide& g, const NeuralTileTargets& t) {
      NeuralSampleSink sink;
      sink.tile = t.tile;
      sink.data = const_cast<NeuralTrainingSample*>(t.samples.data());
      sink.count = static_cast<uint32_t>(t.samples.size());
      g.training_log()->add_tile(sink);
    };
    // "Rank" a gets tiles 0, 3, 4 and b the others, in a scrambled order.
    for (uint32_t t : {4u, 0u, 3u}) feed(a, tiles[t]);
    for (uint32_t t : {5u, 1u, 2u}) feed(b, tiles[t]);
    for (uint32_t r = 0; r < a.rounds(); ++r) {
      std::vector<uint64_t>& x = a.round_accumulators(r);
      std::vector<uint64_t>& y = b.round_accumulators(r);
      ASSERT_EQ(x.size(), y.size());
      for (size_t k = 0; k < x.size(); ++k) x[k] = y[k] = x[k] + y[k];
      a.fold_round(r);
      b.fold_round(r);
    }
    one.train_on(tiles);
  }
  EXPECT_GT(one.stats().steps, 0u);
  EXPECT_TRUE(a == b);
  EXPECT_TRUE(a == one);
}

TEST(NeuralGuide, SaveAndLoadAreExact) {
  NeuralGuide g = make(small_config(), 3);
  std::vector<NeuralTrainingSample> light_targets = random_samples(100, 2, 2.f);
  for (size_t i = 0; i < light_targets.size(); ++i) light_targets[i].bin = kNeuralBins + static_cast<uint32_t>(i % 3);
  g.train_on({{0, random_samples(200, 1, 2.f)}, {1, light_targets}});
  std::stringstream bytes;
  g.save(bytes, 42);
  std::unique_ptr<NeuralGuide> loaded = NeuralGuide::load(bytes, 42);
  EXPECT_TRUE(*loaded == g);
  EXPECT_EQ(loaded->learned_lights(), 3u);
  // The generic loader tells the kinds apart.
  std::stringstream again;
  g.save(again, 42);
  std::unique_ptr<Guide> any = load_guide(again, 42);
  EXPECT_EQ(any->mode(), "neural");
  EXPECT_TRUE(any->same_as(g));
  // Training on goes on identically from the copy (Adam's state included).
  g.train_on({{0, random_samples(64, 3, 1.f)}});
  loaded->train_on({{0, random_samples(64, 3, 1.f)}});
  EXPECT_TRUE(*loaded == g);
}

// The hash table's size (--neural-table) is the state's size: doubling it
// adds levels x features x 2^L parameters. It reaches the view and round-
// trips through a file, and inference and training read the same table: a
// guide trained on targets equal to its own predictions has zero loss. (The
// smallest table, below the default: a view left at the default would read
// past the parameters.)
TEST(NeuralGuide, HashTableSizeIsASettingThatRoundTrips) {
  NeuralGuideConfig c = small_config();
  c.table_log2 = kNeuralMinTableLog2;
  NeuralGuide small = make(c);
  ASSERT_LT(c.table_log2, NeuralGuideConfig{}.table_log2);
  c.table_log2 += 1;
  NeuralGuide large = make(c);
  EXPECT_EQ(large.params().size() - small.params().size(),
            size_t{kNeuralLevels} * kNeuralFeatures * (size_t{1} << kNeuralMinTableLog2));
  EXPECT_EQ(small.view().table_log2, kNeuralMinTableLog2);
  small.train_on({{0, random_samples(200, 1, 2.f)}});
  std::stringstream bytes;
  small.save(bytes, 3);
  std::unique_ptr<NeuralGuide> loaded = NeuralGuide::load(bytes, 3);
  EXPECT_TRUE(*loaded == small);
  EXPECT_EQ(loaded->config().table_log2, kNeuralMinTableLog2);
  std::vector<NeuralTrainingSample> own = random_samples(40, 9, 1.f);
  for (NeuralTrainingSample& s : own) {
    s.target = static_cast<float>(predicted(*loaded, s));
    ASSERT_TRUE(std::isfinite(s.target) && s.target > 0.f);
  }
  std::vector<float> grad;
  EXPECT_LT(loaded->loss_and_gradient(own, &grad), 1e-8);
  // Out of range: refused when made, and when loaded from a file.
  c.table_log2 = kNeuralMaxTableLog2 + 1;
  EXPECT_THROW(make(c), std::runtime_error);
  c.table_log2 = kNeuralMinTableLog2 - 1;
  EXPECT_THROW(make(c), std::runtime_error);
  std::string file = as_version5(bytes.str());
  // The config follows the magic, cereal's endianness byte, the version and
  // the scene fingerprint: width, steps, rate, mixture, floor, targets, table.
  const size_t at = sizeof "tessera-neural-guide" + 1 + 4 + 8 + 4 * 6;
  uint32_t word = 0;
  std::memcpy(&word, file.data() + at, 4);
  ASSERT_EQ(word, kNeuralMinTableLog2) << "the file's layout changed: update the offset";
  for (uint32_t bad : {0u, 40u, kNeuralMaxTableLog2 + 1}) {
    std::memcpy(file.data() + at, &bad, 4);
    std::stringstream damaged(file);
    EXPECT_THROW(NeuralGuide::load(damaged, 3), std::runtime_error) << bad;
  }
  // The learned light count follows the config (after its 64-bit seed).
  file = as_version5(bytes.str());
  std::memcpy(&word, file.data() + at + 4 + 8, 4);
  ASSERT_EQ(word, 0u) << "the file's layout changed: update the offset";
  for (uint32_t bad : {1u, kNeuralMinLights - 1, kNeuralMaxLights + 1}) {
    std::memcpy(file.data() + at + 4 + 8, &bad, 4);
    std::stringstream damaged(file);
    EXPECT_THROW(NeuralGuide::load(damaged, 3), std::runtime_error) << bad;
  }
}

TEST(NeuralGuide, LoadRejectsOtherScenesAndDamage) {
  NeuralGuide g = make(small_config());
  std::stringstream bytes;
  g.save(bytes, 7);
  const std::string s = bytes.str();
  std::stringstream other(s);
  EXPECT_THROW(NeuralGuide::load(other, 8), std::runtime_error);
  std::stringstream cut(s.substr(0, s.size() / 2));
  EXPECT_THROW(NeuralGuide::load(cut, 7), std::runtime_error);
  std::stringstream junk(std::string("tessera-nothing-at-all-here"));
  EXPECT_THROW(load_guide(junk, 7), std::runtime_error);
  // Any damaged byte of the payload fails its checksum before a field is read.
  for (size_t at : {s.size() / 3, s.size() / 2, s.size() - 1}) {
    std::string damaged = s;
    damaged[at] = static_cast<char>(damaged[at] ^ 0x10);
    std::stringstream in(damaged);
    try {
      NeuralGuide::load(in, 7);
      ADD_FAILURE() << "a damaged byte at " << at << " was accepted";
    } catch (const std::runtime_error& e) {
      EXPECT_NE(std::string(e.what()).find("checksum"), std::string::npos) << e.what();
    }
  }
  // A version-5 file (no checksum) still loads.
  std::stringstream v5(as_version5(s));
  EXPECT_TRUE(*NeuralGuide::load(v5, 7) == g);
}

// Version 3 numbered the bins row-major, this version by tiles: a version-3
// file is read with each bin's output moved to its new number (a file saved
// now and relabelled version 3 answers, at bin neural_bin_at(r, c), what the
// saved network answers at bin 12 r + c), and the same network's Adam
// state moves with it. Versions before 3 (and after this one) are refused.
TEST(NeuralGuide, AVersion3FileIsReadWithItsBinsRenumbered) {
  NeuralGuide g = make(small_config());
  g.train_on({{0, random_samples(200, 1, 2.f)}});
  std::stringstream bytes;
  g.save(bytes, 5);
  std::string file = as_version5(bytes.str());
  const size_t at = sizeof "tessera-neural-guide" + 1;  // after the magic and cereal's endianness byte
  uint32_t version = 0;
  std::memcpy(&version, file.data() + at, 4);
  ASSERT_EQ(version, 5u) << "the file's layout changed: update the offset";
  // Versions 3 and 4 end before version 5's mixture fields (a flag, the
  // chosen candidate, two counts). A version-4 file is read as it was
  // saved, with no weight chosen yet: here the network has chosen none.
  file.resize(file.size() - (1 + 4 + 8 + 8));
  version = 4;
  std::memcpy(file.data() + at, &version, 4);
  std::stringstream v4(file);
  std::unique_ptr<NeuralGuide> loaded4 = NeuralGuide::load(v4, 5);
  EXPECT_TRUE(*loaded4 == g);
  EXPECT_TRUE(loaded4->config().learn_mix);
  version = 3;
  std::memcpy(file.data() + at, &version, 4);
  std::stringstream v3(file);
  std::unique_ptr<NeuralGuide> loaded = NeuralGuide::load(v3, 5);
  EXPECT_FALSE(*loaded == g);
  const NeuralGuideView a = g.view(), b = loaded->view();
  NeuralSite sa, sb;
  for (const Vec3& n : {Vec3(0.f, 0.f, 1.f), Vec3(0.f, -1.f, 0.f), glm::normalize(Vec3(0.3f, -0.5f, 0.8f))}) {
    neural_infer(a, Vec3(0.3f, 0.6f, 0.2f), n, &sa);
    neural_infer(b, Vec3(0.3f, 0.6f, 0.2f), n, &sb);
    for (uint32_t r = 0; r < kNeuralGrid; ++r) {
      for (uint32_t c = 0; c < kNeuralGrid; ++c) {
        ASSERT_EQ(neural_site_q(b, sb, neural_bin_at(r, c)), neural_site_q(a, sa, r * kNeuralGrid + c)) << r << ',' << c;
      }
    }
  }
  // Training on moves the renumbered copy's bins as it moves the original's.
  const NeuralLayout L = g.layout();
  std::vector<NeuralTrainingSample> more = random_samples(64, 3, 1.f);
  std::vector<NeuralTrainingSample> renumbered = more;
  for (NeuralTrainingSample& s : renumbered) s.bin = neural_bin_at(s.bin / kNeuralGrid, s.bin % kNeuralGrid);
  g.train_on({{0, more}});
  loaded->train_on({{0, renumbered}});
  for (uint32_t j = 0; j < kNeuralBins; ++j)
    ASSERT_EQ(loaded->params()[L.b3() + neural_bin_at(j / kNeuralGrid, j % kNeuralGrid)], g.params()[L.b3() + j]) << j;
  for (uint32_t old : {1u, 2u, 6u}) {
    std::memcpy(file.data() + at, &old, 4);
    std::stringstream refused(file);
    EXPECT_THROW(NeuralGuide::load(refused, 5), std::runtime_error) << old;
  }
}

// The scene's mixture weight is the candidate under which the learning
// vertices' second moments are smallest: the largest where the guide's
// density is where the integrand is, the smallest it may choose (0.5) where
// it misses it. It is chosen once a pass has enough vertices, kept by save
// and load, and a fixed weight (--guide-mix) is never replaced.
TEST(NeuralGuide, MixtureWeightIsTheCandidateWithTheSmallestSecondMoment) {
  auto pass = [](NeuralGuide& g, Float guide_pdf, int vertices) {
    NeuralSampleSink sink;
    NeuralGuideView v = g.view();
    v.sink = &sink;
    for (int i = 0; i < vertices; ++i) {
      GuideMixSample m;  // a direction drawn from the mixture at the current weight
      m.fcos = 0.5f + 0.001f * static_cast<Float>(i % 7);
      m.bsdf_pdf = 0.3f;
      m.guide_pdf = guide_pdf;
      m.mix_pdf = v.guide_prob * m.guide_pdf + (1.f - v.guide_prob) * m.bsdf_pdf;
      m.nee_value = 0.2f;  // and its next-event sample, whose MIS weight the candidates change too
      m.nee_light_pdf = 1.f;
      m.nee_guide_pdf = guide_pdf;
      m.nee_bsdf_pdf = 0.3f;
      neural_record_mix(v, m, 2.f);
    }
    EXPECT_EQ(sink.mix_vertices, static_cast<uint64_t>(vertices));
    g.training_log()->add_tile(sink);
    for (uint32_t r = 0; r < g.rounds(); ++r) {
      g.round_accumulators(r);
      g.fold_round(r);
    }
  };
  NeuralGuide g = make(small_config());
  EXPECT_EQ(g.mix_weight(), 0.5f);
  pass(g, 3.f, 100);  // too few vertices: nothing chosen
  EXPECT_EQ(g.mix_weight(), 0.5f);
  pass(g, 3.f, 5000);
  EXPECT_EQ(g.mix_candidate(), static_cast<int32_t>(kNeuralMixFirstCandidate + kNeuralMixCandidates - 1));
  EXPECT_EQ(g.mix_weight(), 0.8f);
  EXPECT_EQ(g.view().guide_prob, g.mix_weight());
  EXPECT_EQ(g.stats().mix_weight, g.mix_weight());
  std::stringstream bytes;
  g.save(bytes, 9);
  EXPECT_TRUE(*NeuralGuide::load(bytes, 9) == g);
  pass(g, 0.01f, 5000);
  EXPECT_EQ(g.mix_candidate(), static_cast<int32_t>(kNeuralMixFirstCandidate));
  EXPECT_EQ(g.mix_weight(), 0.5f);
  // Non-finite statistics are left out and counted.
  NeuralSampleSink sink;
  NeuralGuideView v = g.view();
  v.sink = &sink;
  GuideMixSample bad;
  bad.fcos = NAN;
  bad.bsdf_pdf = bad.guide_pdf = bad.mix_pdf = 0.3f;
  neural_record_mix(v, bad, 1.f);
  bad.fcos = 1e30f;
  neural_record_mix(v, bad, 1e30f);
  neural_record_mix(v, bad, NAN);
  EXPECT_EQ(sink.mix_vertices, 0u);
  EXPECT_EQ(sink.mix_rejected, 3u);
  g.training_log()->add_tile(sink);
  for (uint32_t r = 0; r < g.rounds(); ++r) {
    g.round_accumulators(r);
    g.fold_round(r);
  }
  EXPECT_EQ(g.stats().mix_rejected, 3u);
  EXPECT_EQ(g.stats().mix_vertices, 100u + 5000u + 5000u);
  // A fixed weight stays.
  g.set_guide_prob(0.3f);
  EXPECT_FALSE(g.view().learn_mix);
  pass(g, 3.f, 5000);
  EXPECT_EQ(g.mix_weight(), 0.3f);
}

TEST(NeuralGuide, NonFiniteAndHugeTargetsAreRejectedAndCounted) {
  NeuralGuide g = make(small_config());
  NeuralGuideView v = g.view();
  std::vector<NeuralTrainingSample> buffer(16);
  NeuralSampleSink sink;
  sink.data = buffer.data();
  sink.capacity = static_cast<uint32_t>(buffer.size());
  v.sink = &sink;
  NeuralSite site;
  neural_infer(v, Vec3(0.5f), Vec3(0.f, 0.f, 1.f), &site);
  EXPECT_FALSE(neural_record(v, site, 3, std::nanf("")));
  EXPECT_FALSE(neural_record(v, site, 3, INFINITY));
  EXPECT_FALSE(neural_record(v, site, 3, -1.f));
  EXPECT_FALSE(neural_record(v, site, 3, 1e30f));
  EXPECT_TRUE(neural_record(v, site, 3, 0.25f));
  EXPECT_EQ(sink.rejected_nonfinite, 3u);
  EXPECT_EQ(sink.rejected_large, 1u);
  ASSERT_EQ(sink.count, 1u);
  EXPECT_EQ(buffer[0].target, 0.25f);
  EXPECT_EQ(buffer[0].bin, 3u);
  // Huge (accepted) targets: clipped gradients, finite weights.
  std::vector<NeuralTrainingSample> wild = random_samples(64, 9, 1.f);
  for (size_t i = 0; i < wild.size(); i += 3) wild[i].target = 1e5f;
  g.train_on({{0, wild}});
  EXPECT_EQ(g.stats().steps, 8u);
  for (float p : g.params()) ASSERT_TRUE(std::isfinite(p));
  // A NaN that got past the sink (or a NaN weight of the first two
  // layers; a NaN bias is zeroed by the ReLU) poisons its target's
  // gradient: that target is left out of its step (counted), the rest of
  // its tile and the other tile still train.
  std::vector<NeuralTrainingSample> poisoned = random_samples(64, 10, 1.f);
  poisoned[5].target = std::nanf("");
  g.train_on({{0, poisoned}, {1, random_samples(64, 11, 1.f)}});
  EXPECT_EQ(g.stats().nonfinite_gradients, 1u);  // poisoned[5] is in one of the 8 minibatches
  EXPECT_EQ(g.stats().steps, 8u + 8u);
  for (float p : g.params()) ASSERT_TRUE(std::isfinite(p));
}

// The CPU's two copies of the inference (AVX2 and portable) compute the
// same bits: a farm of machines with and without AVX2 renders one image.
TEST(NeuralGuide, AvxAndPortableInferenceAgreeBitForBit) {
  if (!neural_infer_has_avx2()) GTEST_SKIP() << "no AVX2 on this machine";
  NeuralGuide g = make(small_config(16), 4);
  std::vector<NeuralTrainingSample> samples = random_samples(300, 4, 1.f);
  for (size_t i = 0; i < samples.size(); i += 2) samples[i].bin = kNeuralBins + static_cast<uint32_t>(i / 2) % 4;
  g.train_on({{0, samples}});
  const NeuralGuideView v = g.view();
  std::mt19937 rng(8);
  std::uniform_real_distribution<float> u(-0.2f, 1.2f);
  for (int i = 0; i < 200; ++i) {
    const Vec3 p(u(rng), u(rng), u(rng));
    const Vec3 n = glm::normalize(Vec3(u(rng) - 0.5f, u(rng) - 0.5f, u(rng) - 0.5f) + Vec3(0.f, 0.f, 1e-3f));
    NeuralSite a, b;
    neural_infer_avx2(v, p, n, &a);
    neural_infer_portable(v, p, n, &b);
    ASSERT_EQ(a.skipped, b.skipped) << i;
    for (uint32_t j = 0; j < kNeuralBins + 4; ++j) {
      const Float qa = neural_site_q(v, a, j), qb = neural_site_q(v, b, j);
      ASSERT_EQ(std::memcmp(&qa, &qb, sizeof qa), 0) << i << " output " << j;
    }
    ASSERT_EQ(std::memcmp(a.weight, b.weight, sizeof a.weight), 0) << i;
    ASSERT_EQ(std::memcmp(&a.pmf_scale, &b.pmf_scale, sizeof a.pmf_scale), 0) << i;
    ASSERT_EQ(std::memcmp(&a.pmf_floor, &b.pmf_floor, sizeof a.pmf_floor), 0) << i;
    ASSERT_EQ(a.light_prob, b.light_prob);
    ASSERT_GT(a.light_prob, 0.f);
    ASSERT_EQ(std::memcmp(a.light_pmf, b.light_pmf, sizeof(Float) * 4), 0) << i;
    ASSERT_EQ(a.irradiance, b.irradiance);
    ASSERT_EQ(a.qmax, b.qmax);
  }
}

// The inference computes eight lanes at a time (kernels/lanes8.h); each
// output is still the plain definition, bit for bit: the encoding summed
// over corners in order, each layer's sums in input order, exp by
// neural_exp, and the distribution built from them. Widths that fill whole
// lanes and widths that leave a tail.
TEST(NeuralGuide, LaneInferenceEqualsThePlainDefinition) {
  int skipped_blocks = 0, cases = 0;
  // Light counts that leave a group of eight lanes part-filled (3, 9) or
  // full (8, 16): the light outputs are computed eight at a time.
  for (uint32_t width : {5u, 8u, 13u, 16u}) {
    const uint32_t lights = width == 5 ? 3 : width == 8 ? 8 : width == 13 ? 9 : kNeuralMaxLights;
    NeuralGuide g = make(small_config(width), lights);
    std::vector<NeuralTrainingSample> samples = random_samples(200, 7, 1.f);
    for (size_t i = 0; i < samples.size(); i += 3) samples[i].bin = kNeuralBins + static_cast<uint32_t>(i) % lights;
    g.train_on({{0, samples}});
    const NeuralGuideView v = g.view();
    const NeuralLayout L = g.layout();
    const float* P = g.params().data();
    std::mt19937 rng(width);
    std::uniform_real_distribution<float> u(-0.1f, 1.1f);
    for (int t = 0; t < 50; ++t) {
      const Vec3 p(u(rng), u(rng), u(rng));
      const Vec3 n = glm::normalize(Vec3(u(rng) - 0.5f, u(rng) - 0.5f, u(rng) - 0.5f) + Vec3(0.f, 0.f, 1e-3f));
      std::vector<float> in(kNeuralInputs), h1(width), h2(width);
      const Vec3 up = neural_unit_position(v, p);
      for (uint32_t l = 0; l < kNeuralLevels; ++l) {
        uint32_t entry[8];
        Float weight[8];
        neural_level_corners(L.table_size(), l, up, entry, weight);
        for (uint32_t f = 0; f < kNeuralFeatures; ++f) {
          float sum = 0.f;
          for (uint32_t c = 0; c < 8; ++c)
            sum += weight[c] * P[(l * L.table_size() + entry[c]) * kNeuralFeatures + f];
          in[l * kNeuralFeatures + f] = sum;
        }
      }
      in[kNeuralEncoded] = n.x;
      in[kNeuralEncoded + 1] = n.y;
      in[kNeuralEncoded + 2] = n.z;
      auto layer = [&](uint32_t w, uint32_t b, const std::vector<float>& x, uint32_t outs, bool relu) {
        std::vector<float> out(outs);
        for (uint32_t o = 0; o < outs; ++o) {
          float acc = P[b + o];
          for (size_t i = 0; i < x.size(); ++i) acc += P[w + i * outs + o] * x[i];
          out[o] = relu ? (acc > 0.f ? acc : 0.f) : acc;
        }
        return out;
      };
      h1 = layer(L.w1(), L.b1(), in, width, true);
      h2 = layer(L.w2(), L.b2(), h1, width, true);
      const std::vector<float> o = layer(L.w3(), L.b3(), h2, L.outputs(), false);
      NeuralSite site;
      neural_infer_cpu(v, p, n, &site);
      for (uint32_t j = 0; j < L.outputs(); ++j) {
        const float expected = v.scale * neural_exp(o[j]);
        const float got = neural_site_q(v, site, j);
        ASSERT_EQ(std::memcmp(&got, &expected, sizeof expected), 0) << "width " << width << " output " << j;
        if (j < kNeuralBins) {
          const float alone = neural_value(v, p, n, j);  // the value computed alone, as training refreshes it
          ASSERT_EQ(std::memcmp(&alone, &expected, sizeof expected), 0) << "width " << width << " output " << j;
        }
      }
      // The distribution: Q max(cos, 0) summed in eight lanes (bin j in
      // lane j mod 8), the largest Q above the surface, the floor mixed in.
      float lane_sum[8] = {}, lane_max[8] = {}, weighted[kNeuralBins];
      int below[kNeuralBins / 8] = {};
      for (uint32_t j = 0; j < kNeuralBins; ++j) {
        const float c = v.bin_dir_soa[j] * n.x + v.bin_dir_soa[kNeuralBins + j] * n.y +
                        v.bin_dir_soa[2 * kNeuralBins + j] * n.z;
        const float qj = v.scale * neural_exp(o[j]);
        weighted[j] = qj * (c > 0.f ? c : 0.f);
        lane_sum[j % 8] += weighted[j];
        lane_max[j % 8] = std::max(lane_max[j % 8], c > 0.f ? qj : 0.f);
        // A block is skipped exactly where all its bins lie below the surface.
        if (c > 0.f) {
          EXPECT_FALSE((site.skipped >> (j / 8)) & 1u) << j;
        }
        below[j / 8] += c > 0.f ? 0 : 1;
      }
      float total = 0.f, qmax = 0.f;
      for (int k = 0; k < 8; ++k) {
        total += lane_sum[k];
        qmax = std::max(qmax, lane_max[k]);
      }
      ASSERT_EQ(site.irradiance, total * (4.f * kPi / static_cast<float>(kNeuralBins)));
      ASSERT_EQ(neural_value(v, p, n, kNeuralIrradiance), site.irradiance);
      ++cases;
      for (uint32_t b = 0; b < kNeuralBins / 8; ++b) {
        ASSERT_EQ((site.skipped >> b) & 1u, below[b] == 8 ? 1u : 0u) << "block " << b;
        skipped_blocks += below[b] == 8 ? 1 : 0;
      }
      ASSERT_EQ(site.qmax, qmax);
      const float uniform = v.floor / static_cast<float>(kNeuralBins), w = (1.f - v.floor) / total;
      for (uint32_t j = 0; j < kNeuralBins; ++j) ASSERT_EQ(neural_site_pmf(site, j), weighted[j] * w + uniform) << j;
    }
  }
  // Random normals leave some blocks wholly below the surface: the skipping was exercised.
  EXPECT_GT(skipped_blocks, cases / 4);
  EXPECT_LT(skipped_blocks, cases * static_cast<int>(kNeuralBins / 8) / 2);
}

// The levels' corners computed side by side are each level's corners,
// dense and hashed, for every table size.
TEST(NeuralGuide, LaneCornersEqualEachLevelsCorners) {
  std::mt19937 rng(2);
  std::uniform_real_distribution<float> u(0.f, 1.f);
  for (uint32_t log2 = kNeuralMinTableLog2; log2 <= kNeuralMaxTableLog2; ++log2) {
    for (int t = 0; t < 100; ++t) {
      Vec3 p(u(rng), u(rng), u(rng));
      if (t == 0) p = Vec3(1.f, 0.f, 1.f);  // the cube's faces: the last cell, not one beyond
      U8 entry[8];
      F8 weight[8];
      neural_corners8(1u << log2, p, entry, weight);
      for (uint32_t l = 0; l < kNeuralLevels; ++l) {
        uint32_t e[8];
        Float w[8];
        neural_level_corners(1u << log2, l, p, e, w);
        for (uint32_t c = 0; c < 8; ++c) {
          ASSERT_EQ(entry[c][l], e[c]) << log2 << " level " << l << " corner " << c;
          const float wl = weight[c][l];
          ASSERT_EQ(std::memcmp(&wl, &w[c], sizeof wl), 0) << log2 << " level " << l << " corner " << c;
        }
      }
    }
  }
}

// neural_exp is e^x within 2e-6 (relative) over the clamped range, and the
// clamp's value beyond it.
TEST(NeuralGuide, ExpIsExpWithinItsStatedError) {
  double worst = 0.0;
  for (int i = 0; i <= 200000; ++i) {
    const float x = kNeuralMinLog + (kNeuralMaxLog - kNeuralMinLog) * static_cast<float>(i) / 200000.f;
    const double exact = std::exp(static_cast<double>(x));
    worst = std::max(worst, std::fabs(static_cast<double>(neural_exp(x)) - exact) / exact);
  }
  EXPECT_LT(worst, 2e-6);
  EXPECT_EQ(neural_exp(kNeuralMaxLog + 5.f), neural_exp(kNeuralMaxLog));
  EXPECT_EQ(neural_exp(kNeuralMinLog - 5.f), neural_exp(kNeuralMinLog));
  EXPECT_EQ(neural_exp(std::nanf("")), neural_exp(kNeuralMinLog));
  EXPECT_EQ(neural_exp(0.f), 1.f);
}

// neural_exp on eight lanes is neural_exp, including its clamps and NaN.
TEST(NeuralGuide, LaneExpEqualsScalarExp) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> u(-40.f, 30.f);
  for (int t = 0; t < 200; ++t) {
    float x[kLanes8];
    for (uint32_t k = 0; k < kLanes8; ++k) x[k] = u(rng);
    if (t == 0) {
      x[0] = std::nanf("");
      x[1] = INFINITY;
      x[2] = -INFINITY;
      x[3] = kNeuralMinLog;
      x[4] = kNeuralMaxLog;
      x[5] = 0.f;
      x[6] = -0.f;
      x[7] = 1e-30f;
    }
    float y[kLanes8];
    lanes_store(y, neural_exp8(lanes_make(x)));
    for (uint32_t k = 0; k < kLanes8; ++k) {
      const float e = neural_exp(x[k]);
      ASSERT_EQ(std::memcmp(&y[k], &e, sizeof e), 0) << x[k];
    }
  }
}

// The distribution an inference builds is a distribution: positive
// everywhere (the floor), summing to 1, and the density of a sampled
// direction is that of its bin.
TEST(NeuralGuide, InferenceGivesAProperDistribution) {
  NeuralGuide g = make(small_config());
  g.train_on({{0, random_samples(300, 4, 1.f)}});
  const NeuralGuideView v = g.view();
  NeuralSite site;
  neural_infer(v, Vec3(0.3f, 0.6f, 0.2f), glm::normalize(Vec3(0.2f, -0.5f, 1.f)), &site);
  double sum = 0.0;
  for (uint32_t j = 0; j < kNeuralBins; ++j) {
    EXPECT_GT(neural_site_pmf(site, j), 0.f);
    sum += neural_site_pmf(site, j);
  }
  EXPECT_NEAR(sum, 1.0, 1e-5);
  // Sampled directions land in the bin they were drawn for, and bins are
  // drawn with their pmf: chi-square over the 144 bins (143 degrees of
  // freedom; 220 is beyond its 1e-4 quantile).
  std::mt19937 rng(1);
  std::uniform_real_distribution<float> u(0.f, 1.f);
  constexpr int kDraws = 40000;
  std::vector<int> counts(kNeuralBins, 0);
  int elsewhere = 0;
  for (int i = 0; i < kDraws; ++i) {
    Vec3 dir;
    Float pdf = 0.f;
    uint32_t bin = 0;
    ASSERT_TRUE(neural_sample(site, u(rng), Vec2(u(rng), u(rng)), &dir, &pdf, &bin));
    ASSERT_NEAR(glm::length(dir), 1.f, 1e-5f);
    // Mapped back, a direction within float rounding of a bin edge may land
    // in the neighbour (as the table's, guide_sample): rare, never more.
    elsewhere += neural_bin_of(dir) != bin ? 1 : 0;
    ASSERT_NEAR(pdf, neural_site_pmf(site, bin) * kNeuralBins / (4.0 * kPi), 1e-6 * pdf);
    ++counts[bin];
  }
  double chi2 = 0.0;
  for (uint32_t j = 0; j < kNeuralBins; ++j) {
    const double expected = kDraws * static_cast<double>(neural_site_pmf(site, j));
    chi2 += (counts[j] - expected) * (counts[j] - expected) / expected;
  }
  EXPECT_LT(chi2, 220.0);
  EXPECT_LE(elsewhere, kDraws / 1000);

  // A sharp distribution too (a trained network's can be): a few bins with
  // most of the mass, in the first, a middle and the last tile.
  NeuralSite sharp = site;
  double total = 0.0;
  for (uint32_t j = 0; j < kNeuralBins; ++j) {
    sharp.weight[j] = j == 0 || j == 77 || j == 143 ? 0.3f : 1e-3f;
    total += sharp.weight[j];
  }
  sharp.pmf_scale = static_cast<Float>(1.0 / total);
  sharp.pmf_floor = 0.f;
  sharp.has_cdf = false;
  std::fill(counts.begin(), counts.end(), 0);
  for (int i = 0; i < kDraws; ++i) {
    Vec3 dir;
    Float pdf = 0.f;
    uint32_t bin = 0;
    ASSERT_TRUE(neural_sample(sharp, u(rng), Vec2(u(rng), u(rng)), &dir, &pdf, &bin));
    ++counts[bin];
  }
  chi2 = 0.0;
  for (uint32_t j = 0; j < kNeuralBins; ++j) {
    const double expected = kDraws * static_cast<double>(neural_site_pmf(sharp, j));
    chi2 += (counts[j] - expected) * (counts[j] - expected) / expected;
  }
  EXPECT_LT(chi2, 220.0);
}

// A pixel's later samples reuse the network's site at their first vertex
// (NeuralFirstSite) where it lies within the view's reuse_radius on a
// surface facing the same way: the earlier sample's
// distribution, bit for bit, with the vertex's own point and normal for its
// training targets. Farther away, on another surface, at a deeper vertex,
// in a new pixel or without a kept site, the network runs (and renews the
// kept site where the vertex is a path's first).
TEST(NeuralGuide, FirstVertexSiteIsReusedOnlyNearbyOnTheSameSurface) {
  NeuralGuide g = make(small_config(), 3);
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> w(-0.5f, 0.5f);
  for (float& x : g.mutable_params()) x = w(rng);
  NeuralGuideView v = g.view();
  v.trained = true;
  const Float radius = v.reuse_radius;
  ASSERT_EQ(radius, 2.f * v.extent / 256.f);  // two of the finest level's cells (NeuralGuideConfig::reuse_cells)
  const Vec3 n(0.f, 1.f, 0.f), p(0.31f, 0.2f, 0.47f);
  auto fresh = [&](const Vec3& at, const Vec3& normal) {
    NeuralSite s;
    neural_infer_cpu(v, at, normal, &s);
    return s;
  };
  auto same_distribution = [](const NeuralSite& a, const NeuralSite& b) {
    bool same = a.irradiance == b.irradiance && a.qmax == b.qmax && a.light_prob == b.light_prob;
    for (uint32_t j = 0; j < kNeuralBins; ++j) same = same && neural_site_pmf(a, j) == neural_site_pmf(b, j);
    for (uint32_t l = 0; l < 3; ++l) same = same && a.light_pmf[l] == b.light_pmf[l];
    return same;
  };
  const NeuralSite at_p = fresh(p, n);
  const Vec3 near = p + Vec3(0.9f * radius, 0.f, 0.f), far = p + Vec3(0.f, 0.f, 1.1f * radius);
  ASSERT_FALSE(same_distribution(at_p, fresh(far, n))) << "the test needs points the network tells apart";
  NeuralFirstSite first;
  {
    NeuralPathGuide pg(v, &first);
    const int32_t s = pg.locate(p, n);
    EXPECT_FALSE(pg.reused);
    ASSERT_TRUE(first.valid);
    EXPECT_TRUE(same_distribution(pg.site[s], at_p));
    pg.locate(p, n);  // a deeper vertex at the same spot: runs
    EXPECT_FALSE(pg.reused);
    pg.locate(far, n);  // and one elsewhere leaves the kept site alone
    EXPECT_EQ(first.site.p, p);
  }
  {
    NeuralPathGuide pg(v, &first);  // the pixel's next sample
    const int32_t s = pg.locate(near, n);
    EXPECT_TRUE(pg.reused);
    EXPECT_TRUE(same_distribution(pg.site[s], at_p));
    EXPECT_EQ(pg.site[s].p, near);
    EXPECT_EQ(pg.site[s].n, n);
    EXPECT_EQ(first.site.p, p) << "a reuse keeps the kept site";
  }
  {
    NeuralPathGuide pg(v, &first);  // too far on the same surface: runs, and renews the kept site
    const int32_t s = pg.locate(far, n);
    EXPECT_FALSE(pg.reused);
    EXPECT_TRUE(same_distribution(pg.site[s], fresh(far, n)));
    EXPECT_TRUE(same_distribution(first.site, fresh(far, n)));
    EXPECT_EQ(first.site.p, far);
  }
  const Vec3 tilted = glm::normalize(Vec3(0.05f, 1.f, 0.f));
  {
    NeuralPathGuide pg(v, &first);  // another surface through the same spot: runs, renews
    const int32_t s = pg.locate(far, tilted);
    EXPECT_FALSE(pg.reused);
    EXPECT_TRUE(same_distribution(pg.site[s], fresh(far, tilted)));
  }
  {
    NeuralPathGuide pg(v, &first);  // a path that scattered in a medium first (trace_path)
    pg.at_first = false;
    pg.locate(far, tilted);
    EXPECT_FALSE(pg.reused);
  }
  {
    NeuralPathGuide pg(v, &first);  // (what the new pixel below would reuse)
    pg.locate(far, tilted);
    EXPECT_TRUE(pg.reused);
  }
  first.valid = false;  // a new pixel
  {
    NeuralPathGuide pg(v, &first);
    pg.locate(far, tilted);
    EXPECT_FALSE(pg.reused);
  }
  {
    NeuralPathGuide pg(v);  // nothing kept (the device, the bvh backend)
    pg.locate(far, n);
    EXPECT_FALSE(pg.reused);
  }
}

}  // namespace
}  // namespace tessera
