// RenderOptions::target_error: the render stops after the first pass whose
// estimated relMSE is at or below the target, or at the spp limit or time
// budget if one of those comes first; it never stops on an estimate made
// from too few samples, and a resumed render stops where an uninterrupted
// one does.
#include <gtest/gtest.h>

#include <cstdio>
#include <string>

#include "render/error_estimate.h"
#include "furnace_scene.h"
#include "render_helpers.h"

namespace tessera {
namespace {

// The closed-sphere furnace (see furnace_test.cpp), 16x16: estimated relMSE
// ~0.12/spp with NEE, so 0.01 is reached after a handful of passes.
class TargetError : public ::testing::Test {
 protected:
  TargetError() : scene_(load_pbrt_string(testing::furnace_scene(0.5, 5, 16, 0), "<furnace>", ".")), embree_(scene_) {}

  // Unlimited spp, a generous time budget (never reached: the test renders
  // well under a second), the given target.
  RenderOptions options(double target) const {
    RenderOptions opt;
    opt.progress = false;
    opt.spp = 0;
    opt.time_budget_s = 60;
    opt.target_error = target;
    opt.max_depth = scene_.desc().max_depth;
    opt.seed = 5;
    return opt;
  }
  RenderResult render_with(const RenderOptions& opt, const RenderResult* resume = nullptr) {
    return render(scene_, embree_, opt, nullptr, resume);
  }
  SceneData scene_;
  EmbreeBackend embree_;
};

// Every pass before the last was above the target (or not yet estimable),
// the last at or below it: the render stopped at the first pass it could.
void expect_stopped_at_first_pass_below(const RenderStats& s, double target) {
  ASSERT_FALSE(s.pass_stats.empty());
  EXPECT_LE(s.pass_stats.back().estimated_rel_mse, target);
  EXPECT_GE(s.pass_stats.back().estimated_rel_mse, 0.0);
  for (size_t i = 0; i + 1 < s.pass_stats.size(); ++i) {
    const double e = s.pass_stats[i].estimated_rel_mse;
    EXPECT_TRUE(e < 0 || e > target) << "pass " << i << " already had " << e << " <= " << target;
  }
}

TEST_F(TargetError, StopsAtFirstPassAtOrBelowTarget) {
  constexpr double kTarget = 0.01;
  RenderResult r = render_with(options(kTarget));
  const RenderStats& s = r.stats;
  EXPECT_EQ(s.stop_reason, "target-error");
  EXPECT_EQ(s.target_error, kTarget);
  EXPECT_LE(s.estimated_rel_mse, kTarget);
  EXPECT_GE(s.estimated_rel_mse, 0.0);
  // The figure reported is the estimate of the film returned.
  const ErrorEstimate e = estimate_rel_mse(r.film);
  ASSERT_TRUE(e.valid);
  EXPECT_EQ(s.estimated_rel_mse, e.rel_mse);
  EXPECT_EQ(s.estimated_rel_mse, s.pass_stats.back().estimated_rel_mse);
  expect_stopped_at_first_pass_below(s, kTarget);
  // Not trivially at the first estimable pass, and well short of anything a
  // time budget would allow.
  ASSERT_GE(s.pass_stats.size(), 2u);
  EXPECT_GT(s.pass_stats[s.pass_stats.size() - 2].estimated_rel_mse, kTarget);
  EXPECT_GT(s.spp, kMinSppForErrorEstimate);
  EXPECT_LT(s.spp, 256u);
  EXPECT_EQ(s.passes, s.pass_stats.size());
}

TEST_F(TargetError, ImpossibleTargetStopsOnTime) {
  RenderOptions opt = options(1e-12);
  opt.time_budget_s = 0.5;
  RenderResult r = render_with(opt);
  EXPECT_EQ(r.stats.stop_reason, "time");
  EXPECT_GE(r.stats.spp, kMinSppForErrorEstimate);
  EXPECT_GT(r.stats.estimated_rel_mse, 1e-12);
  EXPECT_EQ(r.stats.target_error, 1e-12);
}

TEST_F(TargetError, SppLimitWinsWhenItComesFirst) {
  RenderOptions opt = options(1e-6);  // ~100k spp away
  opt.spp = 16;
  RenderResult r = render_with(opt);
  EXPECT_EQ(r.stats.stop_reason, "spp");
  EXPECT_EQ(r.stats.spp, 16u);
  EXPECT_GT(r.stats.estimated_rel_mse, 1e-6);
}

TEST_F(TargetError, TargetWinsOverDistantSppLimitWithTheSameImage) {
  RenderResult unlimited = render_with(options(0.01));
  RenderOptions opt = options(0.01);
  opt.spp = 4096;
  opt.time_budget_s = 0;
  RenderResult limited = render_with(opt);
  EXPECT_EQ(limited.stats.stop_reason, "target-error");
  EXPECT_EQ(limited.stats.spp, unlimited.stats.spp);
  EXPECT_TRUE(testing::films_identical(limited.film, unlimited.film));
}

TEST_F(TargetError, NeverStopsOnTooFewSamples) {
  // A target any estimate meets: the render still goes on until the
  // estimate exists (4 spp: passes of 1, 1 and 2), then stops.
  RenderResult r = render_with(options(1e9));
  EXPECT_EQ(r.stats.stop_reason, "target-error");
  EXPECT_EQ(r.stats.spp, kMinSppForErrorEstimate);
  ASSERT_EQ(r.stats.pass_stats.size(), 3u);
  EXPECT_LT(r.stats.pass_stats[0].estimated_rel_mse, 0.0);
  EXPECT_LT(r.stats.pass_stats[1].estimated_rel_mse, 0.0);
  EXPECT_GE(r.stats.pass_stats[2].estimated_rel_mse, 0.0);
}

TEST_F(TargetError, ResumedRenderStopsWhereAnUninterruptedOneDoes) {
  RenderResult whole = render_with(options(0.01));
  ASSERT_EQ(whole.stats.stop_reason, "target-error");
  ASSERT_GT(whole.stats.spp, 8u);
  RenderOptions first = options(0.0);
  first.spp = 8;
  first.time_budget_s = 0;
  RenderResult part = render_with(first);
  ASSERT_EQ(part.stats.spp, 8u);
  RenderResult resumed = render_with(options(0.01), &part);
  EXPECT_EQ(resumed.stats.stop_reason, "target-error");
  EXPECT_EQ(resumed.stats.spp, whole.stats.spp);
  EXPECT_EQ(resumed.stats.passes, whole.stats.passes);
  EXPECT_TRUE(testing::films_identical(resumed.film, whole.film));
  EXPECT_EQ(resumed.stats.estimated_rel_mse, whole.stats.estimated_rel_mse);
  expect_stopped_at_first_pass_below(resumed.stats, 0.01);

  // Resumed from a render already at the target: no further pass.
  RenderResult again = render_with(options(0.01), &whole);
  EXPECT_EQ(again.stats.stop_reason, "target-error");
  EXPECT_EQ(again.stats.spp, whole.stats.spp);
  EXPECT_EQ(again.stats.passes, whole.stats.passes);
}

// Under --time the next pass is the schedule's where it fits, else cut to
// the samples that fit (the last pass's rendering time per sample per
// pixel plus its learning), else the render stops.
TEST(TimeBudget, NextPassIsCutToTheTimeLeft) {
  PassStats last;
  last.spp = 8;
  last.seconds = 1.0;       // 0.1 s per spp rendering, then 0.2 s learning
  last.guide_seconds = 0.2;
  EXPECT_EQ(pass_spp_within_budget(8, 5.0, last), 8u);
  EXPECT_EQ(pass_spp_within_budget(8, 1.0 + 1e-9, last), 8u);
  EXPECT_EQ(pass_spp_within_budget(8, 0.75, last), 5u);   // 0.2 + 5 x 0.1 <= 0.75 < 0.2 + 6 x 0.1
  EXPECT_EQ(pass_spp_within_budget(8, 0.31, last), 1u);
  EXPECT_EQ(pass_spp_within_budget(8, 0.29, last), 0u);
  EXPECT_EQ(pass_spp_within_budget(8, 0.0, last), 0u);
  EXPECT_EQ(pass_spp_within_budget(8, -1.0, last), 0u);
  EXPECT_EQ(pass_spp_within_budget(1, 0.31, last), 1u);
  EXPECT_EQ(pass_spp_within_budget(1, 0.29, last), 0u);
  // A pass that was all learning (or a clock that did not move): nothing
  // to scale, so the next pass runs whole while the learning fits.
  last.guide_seconds = 2.0;
  EXPECT_EQ(pass_spp_within_budget(8, 1.5, last), 8u);
  EXPECT_EQ(pass_spp_within_budget(8, 0.5, last), 0u);
  PassStats unmeasured;
  EXPECT_EQ(pass_spp_within_budget(8, 0.5, unmeasured), 8u);
}

}  // namespace
}  // namespace tessera
