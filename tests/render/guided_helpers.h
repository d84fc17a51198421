// Helpers for the guided-rendering tests: a scene with its BVH rendered with
// or without a guide, and statistical comparison of two renders.
#pragma once

#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "../film_stats.h"
#include "render_helpers.h"

namespace tessera::testing {

// One scene + its BVH, rendered with or without a guide.
struct GuidedScene {
  SceneData scene;
  mutable EmbreeBackend embree;  // its per-pass state changes while it renders
  explicit GuidedScene(SceneDesc d) : scene(std::move(d)), embree(scene) {}

  GuideField make_guide(const GuideConfig& cfg = {}) const {
    return GuideField(cfg, scene.bounds().lo, scene.bounds().hi, scene.view().num_lights, scene.max_emitted_radiance());
  }
  std::unique_ptr<NeuralGuide> make_neural(const NeuralGuideConfig& cfg = {}) const {
    return std::make_unique<NeuralGuide>(cfg, scene.bounds().lo, scene.bounds().hi, scene.max_emitted_radiance(),
                                         scene.view().num_lights);
  }
  RenderResult run(Guide* guide, RenderOptions opt = {}) const {
    opt.progress = false;
    opt.spp = static_cast<uint32_t>(scene.desc().spp);
    opt.max_depth = scene.desc().max_depth;
    return render(scene, embree, opt, guide);
  }
};

inline const char* rule_name(GuideTarget t) { return t == GuideTarget::QLearning ? "qlearning" : "qtable"; }

inline GuideConfig config_with(GuideTarget target, Float guide_prob = 0.5f) {
  GuideConfig cfg;
  cfg.target = target;
  cfg.guide_prob = guide_prob;
  return cfg;
}

// Two independent estimates of the same image agree when every channel's
// means differ by less than 4 combined standard errors: for one channel a
// false alarm has probability ~6e-5 (normal approximation, fine at > 10^4
// samples per image), ~2e-4 for the three.
inline void expect_agree(const ChannelStats& a, const ChannelStats& b, const std::string& what) {
  for (int c = 0; c < 3; ++c) {
    const double tol = 4.0 * std::sqrt(a.se[c] * a.se[c] + b.se[c] * b.se[c]);
    EXPECT_NEAR(a.mean[c], b.mean[c], tol)
        << what << ", channel " << c << ", standard errors " << a.se[c] << " and " << b.se[c];
  }
}

// The comparison means something only if it can see a bias of a few percent.
inline void expect_precise(const ChannelStats& s, double rel, const std::string& what) {
  for (int c = 0; c < 3; ++c) {
    ASSERT_GT(s.mean[c], 0.0) << what;
    EXPECT_LT(s.se[c], rel * s.mean[c]) << what << ": too noisy to detect a bias, channel " << c;
  }
}

inline bool all_finite(const Film& film) {
  for (float v : film_mean(film).rgb)
    if (!std::isfinite(v)) return false;
  return true;
}

inline SceneDesc shipped(const char* name, int w, int h, int spp, int max_depth) {
  SceneDesc d = load_pbrt_file(testing::source_dir() + "/scenes/" + name + ".pbrt");
  d.film.xres = w;
  d.film.yres = h;
  d.spp = spp;
  d.max_depth = max_depth;
  return d;
}

// Seeds for renders that are compared statistically: guided and unguided
// renders with the same seed share their first random numbers (camera ray,
// first light sample) and would be correlated.
inline RenderOptions seeded(uint64_t seed) {
  RenderOptions opt;
  opt.seed = seed;
  return opt;
}

}  // namespace tessera::testing
