// Guide-cache options shared by `render` and `guide-viz`: which rule learns,
// its memory budget, and loading/saving a cache.
#pragma once

#include <CLI/CLI.hpp>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "guidecache/table/guide_field.h"
#include "guidecache/neural/neural_guide.h"
#include "render/renderer.h"
#include "render/scene_data.h"

namespace tessera {

struct GuideArgs {
  std::string mode = "auto";  // auto | none | qtable | qlearning | neural
  double budget_mb = 4.0;
  std::optional<double> mix;  // probability of sampling a direction from the guide (default 0.5)
  int64_t split = 0;
  int64_t grid = 12;          // direction bins per side of the equal-area square
  // Learning schedule: every sample trains the guide up to learn_spp samples
  // per pixel, then every learn_every-th sample does (with the taper, ever
  // more rarely: GuideLearnSchedule).
  int64_t learn_spp = GuideLearnSchedule{}.all_spp;
  int64_t learn_every = GuideLearnSchedule{}.every;
  std::string learn_taper = "on";  // on | off
  std::string roulette = "guided";  // guided | throughput
  double roulette_window = kGuidedRouletteWindow;
  double max_ratio = kMaxGuideRatio;
  std::string nee = "learned";      // learned | always: next-event estimation's probability per cell
  std::string in, out;
  // --guide neural
  int64_t neural_width = NeuralGuideConfig{}.width;
  int64_t neural_steps = NeuralGuideConfig{}.steps_per_pass;
  double neural_lr = NeuralGuideConfig{}.learning_rate;
  int64_t neural_targets = NeuralGuideConfig{}.tile_targets;
  int64_t neural_table_log2 = NeuralGuideConfig{}.table_log2;
  // The --neural-* options given on the command line: a network loaded
  // with --guide-in or --resume keeps the settings it was trained with, so
  // a given one that differs is an error, not silently ignored.
  std::vector<std::string> neural_given;
};

void add_guide_options(CLI::App* cmd, GuideArgs& args);

// Copies the learning schedule (--guide-learn-spp / --guide-learn-every) and
// the roulette rule (--guide-roulette) into a render's options.
void apply_guide_render_options(const GuideArgs& args, RenderOptions* options);

// The effects set decides "auto": guiding needs a surface that scatters
// non-specularly (diffuse or glossy) lit by some light.
bool guiding_helps(uint32_t effects);

// nullptr when guiding is off. Loads --guide-in when given (its learning rule
// and budget then come from the file). *why explains the choice for the log.
std::unique_ptr<Guide> make_guide(const GuideArgs& args, const SceneData& scene, std::string* why);

// Throws std::runtime_error where a guide loaded from a file or a checkpoint
// contradicts the --neural-* options given: a network trained with other
// settings, or a table guide.
void check_guide_options(const GuideArgs& args, const Guide& guide);

// Throws std::runtime_error where a loaded guide does not fit the scene in a
// way the scene fingerprint cannot tell (a crafted file: the lights a table
// or a network learns selection over).
void check_guide_fits_scene(const Guide& guide, const SceneData& scene);

// Writes the cache to --guide-out when given (temp file + rename: never a torn file).
void save_guide(const GuideArgs& args, const Guide& guide, const SceneData& scene);

// One line for the log: which guide, why, and its main settings.
std::string describe_guide(const Guide& guide);

}  // namespace tessera
