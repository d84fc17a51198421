#include "app/guide_setup.h"

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <limits>
#include <sstream>
#include <stdexcept>

#include "app/commands.h"
#include "kernels/effects.h"
#include "render/output_file.h"
#include "render/renderer.h"

namespace tessera {

void add_guide_options(CLI::App* cmd, GuideArgs& a) {
  cmd->add_option("--guide", a.mode,
                  "Learned guiding: qtable (expected SARSA), qlearning (max rule), neural (an MLP over a hash-grid "
                  "encoding, trained with expected SARSA), none; auto = the scene's effects decide")
      ->check(CLI::IsMember({"auto", "none", "qtable", "qlearning", "neural"}));
  cmd->add_option("--guide-budget", a.budget_mb, "Guide cache memory budget in MB (cells stop refining there)")
      ->check(finite_range(0.1, 1048576.0));
  cmd->add_option("--guide-mix", a.mix,
                  "Probability of sampling a direction from the guide instead of the BSDF, the same in every cell "
                  "(default: learned, per cell for the table, per scene for the network)")
      ->check(finite_range(0.0, 1.0));
  cmd->add_option("--guide-split", a.split, "Updates a cell takes before it splits (0 = 24 per direction bin)")
      ->check(CLI::Range(int64_t(0), int64_t(1) << 40));
  cmd->add_option("--guide-grid", a.grid, "Direction bins per side of the equal-area square (bins = grid^2)")
      ->check(CLI::Range(2, 64));
  cmd->add_option("--guide-learn-spp", a.learn_spp,
                  "Every sample trains the guide up to this many samples per pixel")
      ->check(CLI::Range(int64_t(0), int64_t(1) << 30));
  cmd->add_option("--guide-learn-every", a.learn_every,
                  "After --guide-learn-spp, every N-th sample per pixel trains the guide (0 = none do)")
      ->check(CLI::Range(int64_t(0), int64_t(1) << 30));
  cmd->add_option("--guide-learn-taper", a.learn_taper,
                  "on: past 16*K samples per pixel (--guide-learn-every K; or --guide-learn-spp if larger) the "
                  "gap between learning samples doubles each time the sample count doubles; off: every K-th "
                  "sample learns throughout")
      ->check(CLI::IsMember({"on", "off"}));
  cmd->add_option("--guide-roulette", a.roulette,
                  "Russian roulette of guided renders: guided (by the guide's prediction of what a path will "
                  "bring) or throughput (pbrt-v4's rule)")
      ->check(CLI::IsMember({"guided", "throughput"}));
  cmd->add_option("--guide-roulette-window", a.roulette_window,
                  "Guided roulette: a path the guide expects to bring at least 1/W of its predicted light always "
                  "survives. Smaller W: shorter paths, less time per sample, more noise per sample (default 2)")
      ->check(finite_range(0.01, 100.0));
  cmd->add_option("--guide-max-ratio", a.max_ratio,
                  "A path samples its BSDF alone once guided sampling has raised its weight R times over: keeps very "
                  "deep paths from heavy-tailed weights. Larger R: guiding at more vertices, more variance in deep "
                  "paths (default " + std::to_string(static_cast<int>(kMaxGuideRatio)) + ")")
      ->check(finite_range(1.0, 1e30));
  cmd->add_option("--guide-nee", a.nee,
                  "Next-event estimation of guided renders: learned (cells whose shadow rays bring little trace "
                  "them less often) or always (every vertex)")
      ->check(CLI::IsMember({"learned", "always"}));
  cmd->add_option("--guide-in", a.in, "Start from a guide cache saved by --guide-out (same scene only)");
  cmd->add_option("--guide-out", a.out, "Save the learned guide cache after rendering");
  cmd->add_option("--neural-width", a.neural_width, "--guide neural: neurons per hidden layer (two layers)")
      ->check(CLI::Range(int64_t{1}, int64_t{kNeuralMaxWidth}))
      ->each([&a](const std::string&) { a.neural_given.push_back("--neural-width"); });
  cmd->add_option("--neural-steps", a.neural_steps,
                  "--guide neural: Adam steps after each learning pass (in a farm, each sums the gradients of every rank)")
      ->check(CLI::Range(int64_t{1}, int64_t{1024}))
      ->each([&a](const std::string&) { a.neural_given.push_back("--neural-steps"); });
  cmd->add_option("--neural-lr", a.neural_lr, "--guide neural: Adam's learning rate")->check(finite_range(1e-6, 1.0))
      ->each([&a](const std::string&) { a.neural_given.push_back("--neural-lr"); });
  cmd->add_option("--neural-targets", a.neural_targets,
                  "--guide neural: learning targets a tile keeps per learning pass, on average (training time grows with it)")
      ->check(CLI::Range(int64_t{1}, int64_t{1} << 20))
      ->each([&a](const std::string&) { a.neural_given.push_back("--neural-targets"); });
  cmd->add_option("--neural-table", a.neural_table_log2,
                  "--guide neural: entries per hash-grid level, as a power of two (default " +
                      std::to_string(NeuralGuideConfig{}.table_log2) +
                      "; 12 is the largest whose state stays under 1 MB; the state doubles with each step)")
      ->check(CLI::Range(int64_t{kNeuralMinTableLog2}, int64_t{kNeuralMaxTableLog2}))
      ->each([&a](const std::string&) { a.neural_given.push_back("--neural-table"); });
}

void apply_guide_render_options(const GuideArgs& a, RenderOptions* opt) {
  opt->guide_learn = {static_cast<uint32_t>(a.learn_spp), static_cast<uint32_t>(a.learn_every), a.learn_taper == "on"};
  opt->guide_roulette = a.roulette == "guided";
  opt->guide_roulette_window = static_cast<float>(a.roulette_window);
  opt->guide_max_ratio = static_cast<float>(a.max_ratio);
}

bool guiding_helps(uint32_t effects) {
  const bool scatters = (effects & (kEffectDiffuse | kEffectGlossy)) != 0;
  const bool lit = (effects & (kEffectAreaLights | kEffectDeltaLights | kEffectEnvironment)) != 0;
  return scatters && lit;
}

// A network keeps the settings it was trained with (its shape, and how it
// trains, are saved with it): a --neural-* option that differs from the
// loaded network's would be silently ignored, so it is refused instead.
void check_guide_options(const GuideArgs& a, const Guide& guide) {
  const auto* net = dynamic_cast<const NeuralGuide*>(&guide);
  if (!net) {
    if (!a.neural_given.empty())
      throw std::runtime_error("holds a " + guide.mode() + " guide, and " + a.neural_given[0] + " is for --guide neural");
    return;
  }
  const NeuralGuideConfig& c = net->config();
  auto refuse = [](const std::string& option, const std::string& given, const std::string& saved) {
    throw std::runtime_error("its network was trained with " + option + " " + saved + ", not " + given +
                             " (a loaded network keeps its settings: drop the option, or train a new network)");
  };
  // Shortest that tells them apart: the learning rate is compared as the network stores it.
  auto rates = [](Float given, Float saved) {
    for (int digits : {6, std::numeric_limits<Float>::max_digits10}) {
      std::ostringstream g, s;
      g << std::setprecision(digits) << given;
      s << std::setprecision(digits) << saved;
      if (g.str() != s.str()) return std::make_pair(g.str(), s.str());
    }
    return std::make_pair(std::string(), std::string());
  };
  for (const std::string& o : a.neural_given) {
    if (o == "--neural-width" && a.neural_width != int64_t{c.width})
      refuse(o, std::to_string(a.neural_width), std::to_string(c.width));
    if (o == "--neural-steps" && a.neural_steps != int64_t{c.steps_per_pass})
      refuse(o, std::to_string(a.neural_steps), std::to_string(c.steps_per_pass));
    if (o == "--neural-lr" && static_cast<Float>(a.neural_lr) != c.learning_rate) {
      const auto [given, saved] = rates(static_cast<Float>(a.neural_lr), c.learning_rate);
      refuse(o, given, saved);
    }
    if (o == "--neural-targets" && a.neural_targets != int64_t{c.tile_targets})
      refuse(o, std::to_string(a.neural_targets), std::to_string(c.tile_targets));
    if (o == "--neural-table" && a.neural_table_log2 != int64_t{c.table_log2})
      refuse(o, std::to_string(a.neural_table_log2), std::to_string(c.table_log2));
  }
}

std::unique_ptr<Guide> make_guide(const GuideArgs& a, const SceneData& scene, std::string* why) {
  std::string mode = a.mode;
  if (mode == "auto") {
    mode = guiding_helps(scene.effects()) ? "qtable" : "none";
    *why = mode == "qtable" ? "auto: the scene has non-specular surfaces and lights"
                            : "auto: no non-specular surface is lit, nothing to guide";
  } else {
    *why = "--guide " + mode;
  }
  if (mode == "none" && a.mode == "auto" && !a.in.empty()) mode = "qtable";  // auto with a file: the file decides
  // Without a file, --neural-* options shape a new network (a loaded guide
  // is held to them by check_guide_options).
  if (a.in.empty() && mode != "neural" && !a.neural_given.empty())
    throw std::runtime_error(a.neural_given[0] + " is for --guide neural; the guide is " + mode + " (" + *why + ")");
  if (mode == "none") {
    if (!a.in.empty()) throw std::runtime_error("--guide none and --guide-in " + a.in + " contradict each other");
    // The file asked for would not be written: refused before rendering, not found missing after.
    if (!a.out.empty()) throw std::runtime_error("--guide-out " + a.out + ": no guide is learned to save (" + *why + ")");
    return nullptr;
  }
  if (!a.in.empty()) {
    std::ifstream f(a.in, std::ios::binary);
    if (!f) throw std::runtime_error("--guide-in: cannot open " + a.in);
    try {
      std::unique_ptr<Guide> g = load_guide(f, scene.fingerprint());
      check_guide_fits_scene(*g, scene);
      // A table file serves qtable and qlearning (its rule comes from the file); auto takes either kind.
      if (a.mode != "auto" && (g->mode() == "neural") != (mode == "neural"))
        throw std::runtime_error("holds a " + g->mode() + " guide, not --guide " + mode);
      check_guide_options(a, *g);
      if (a.mix) g->set_guide_prob(static_cast<Float>(*a.mix));
      if (auto* field = dynamic_cast<GuideField*>(g.get())) field->set_nee_gain(a.nee == "always" ? 0.f : GuideConfig{}.nee_gain);
      *why = "loaded from " + a.in;
      return g;
    } catch (const std::exception& e) {
      throw std::runtime_error("--guide-in " + a.in + ": " + e.what());
    }
  }
  const Bounds& b = scene.bounds();
  if (mode == "neural") {
    NeuralGuideConfig nc;
    nc.width = static_cast<uint32_t>(a.neural_width);
    nc.steps_per_pass = static_cast<uint32_t>(a.neural_steps);
    nc.learning_rate = static_cast<Float>(a.neural_lr);
    nc.tile_targets = static_cast<uint32_t>(a.neural_targets);
    nc.table_log2 = static_cast<uint32_t>(a.neural_table_log2);
    if (a.mix) {
      nc.guide_prob = static_cast<Float>(*a.mix);
      nc.learn_mix = false;
    }
    return std::make_unique<NeuralGuide>(nc, b.lo, b.hi, scene.max_emitted_radiance(), scene.view().num_lights);
  }
  GuideConfig cfg;
  cfg.budget_bytes = static_cast<uint64_t>(std::llround(a.budget_mb * 1048576.0));
  if (a.mix) {
    cfg.guide_prob = static_cast<Float>(*a.mix);
    cfg.learn_mix = false;
  }
  cfg.split_updates = static_cast<uint64_t>(a.split);
  cfg.grid = static_cast<uint32_t>(a.grid);
  if (a.nee == "always") cfg.nee_gain = 0.f;
  cfg.target = mode == "qlearning" ? GuideTarget::QLearning : GuideTarget::ExpectedSarsa;
  return std::make_unique<GuideField>(cfg, b.lo, b.hi, scene.view().num_lights, scene.max_emitted_radiance());
}

void save_guide(const GuideArgs& a, const Guide& guide, const SceneData& scene) {
  if (a.out.empty()) return;
  write_output(a.out, [&](const std::string& tmp) {
    std::ofstream f(tmp, std::ios::binary | std::ios::trunc);
    if (!f) throw std::runtime_error("--guide-out: cannot write " + tmp);
    guide.save(f, scene.fingerprint());
    f.close();
    if (!f) throw std::runtime_error("--guide-out: cannot write " + tmp);
  });
}

void check_guide_fits_scene(const Guide& guide, const SceneData& scene) {
  // A table learns selection over every light of the scene, or none.
  if (const auto* f = dynamic_cast<const GuideField*>(&guide)) {
    const uint32_t lights = scene.view().num_lights;
    if (f->learned_lights() != 0 && f->learned_lights() != lights)
      throw std::runtime_error("the table learns selection over " + std::to_string(f->learned_lights()) +
                               " lights, the scene has " + std::to_string(lights));
    return;
  }
  const auto* n = dynamic_cast<const NeuralGuide*>(&guide);
  if (!n) return;
  const uint32_t expected = NeuralGuide::learned_lights_for(scene.view().num_lights);
  if (n->learned_lights() != expected)
    throw std::runtime_error("the network learns selection over " + std::to_string(n->learned_lights()) +
                             " lights, the scene needs " + std::to_string(expected));
}

std::string describe_guide(const Guide& guide) {
  char b[256];
  if (const auto* f = dynamic_cast<const GuideField*>(&guide)) {
    const GuideConfig& c = f->config();
    std::snprintf(b, sizeof b, "%u direction bins, %s light selection, %s next-event estimation, budget %.0f MB",
                  c.grid * c.grid, f->learned_lights() ? "learned" : "power-based",
                  c.nee_gain > 0.f ? "learned" : "every-vertex", c.budget_bytes / 1048576.0);
  } else if (const auto* n = dynamic_cast<const NeuralGuide*>(&guide)) {
    const NeuralGuideConfig& c = n->config();
    std::snprintf(b, sizeof b,
                  "hash grid %u levels x %u entries x %u features + normal, MLP 2 x %u, %u direction bins, "
                  "%s light selection, %u Adam steps per pass (learning rate %g), %.2f MB",
                  kNeuralLevels, 1u << c.table_log2, kNeuralFeatures, c.width, kNeuralBins,
                  n->learned_lights() ? "learned" : "power-based", c.steps_per_pass,
                  static_cast<double>(c.learning_rate), n->stats().bytes / 1048576.0);
  } else {
    return guide.mode();
  }
  return b;
}

}  // namespace tessera
