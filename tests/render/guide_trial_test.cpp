// --guide auto's trial (render/guide_trial.h): windows of alternating guided
// and unguided passes once the guide has learned; each method's relative
// variance per sample is a median over pixel groups, robust to a few heavy
// samples; no single window decides; the final decision takes the loser's
// samples out of the image where they are much noisier, and the render then
// renders them again with the winner. The image stays unbiased whichever way
// the trial goes, and depends on the samples alone (any thread count, resume).
#include <gtest/gtest.h>

#include <random>
#include <sstream>

#include "furnace_scene.h"
#include "guided_helpers.h"
#include "master/checkpoint.h"
#include "render/error_estimate.h"
#include "render/guide_trial.h"

namespace tessera {
namespace {

using testing::channel_stats;
using testing::GuidedScene;

// A pixel's accumulators after n samples of value v (+-d alternately).
PixelAccum pixel(uint64_t n, double v, double d) {
  PixelAccum p;
  for (uint64_t i = 0; i < n; ++i) {
    const double x = v + ((i & 1) ? d : -d);
    for (int c = 0; c < 3; ++c) {
      p.sum[c] += x;
      p.sum_sq[c] += x * x;
    }
  }
  p.n = n;
  return p;
}

Film film_of(uint64_t n, double v, double d) {
  Film f(2, 2);
  for (PixelAccum& p : f.pixels) p = pixel(n, v, d);
  return f;
}

// Adds a pass of n samples of value v +- d to every pixel.
Film after_pass(const Film& before, uint64_t n, double v, double d) {
  Film f = before;
  for (PixelAccum& p : f.pixels) {
    const PixelAccum add = pixel(n, v, d);
    for (int c = 0; c < 3; ++c) {
      p.sum[c] += add.sum[c];
      p.sum_sq[c] += add.sum_sq[c];
    }
    p.n += n;
  }
  return f;
}

TEST(GuideTrial, WindowsStartAtDoublingsAndAlternateGuidedFirst) {
  GuideTrial t;
  EXPECT_EQ(guide_trial_next_pass(t, 100), TrialPass::None);  // no trial asked for
  EXPECT_TRUE(guide_trial_guiding(t));
  guide_trial_start(t, kGuideTrialMatureSamples);  // a guide mature at once
  EXPECT_EQ(guide_trial_next_pass(t, kGuideTrialStartSpp - 1), TrialPass::None);
  EXPECT_EQ(guide_trial_next_pass(t, kGuideTrialStartSpp), TrialPass::Guided);
  Film f = film_of(kGuideTrialStartSpp, 1.0, 0.1);
  for (uint32_t k = 0; k < kGuideTrialPassesPerMethod; ++k) {
    Film g = after_pass(f, 8, 1.0, 0.1);
    guide_trial_record(t, true, true, g, f.pixels, 8, 32, 1000);
    EXPECT_EQ(guide_trial_next_pass(t, 0), TrialPass::None);  // before the window: no trial pass
    EXPECT_EQ(guide_trial_next_pass(t, kGuideTrialStartSpp + 8), TrialPass::Unguided);
    f = after_pass(g, 8, 1.0, 0.1);
    guide_trial_record(t, true, false, f, g.pixels, 8, 32, 1000);
  }
  // One window never decides; the next starts at the doubling.
  EXPECT_EQ(t.state, GuideTrialState::Pending);
  EXPECT_EQ(t.windows_done, 1u);
  EXPECT_EQ(guide_trial_next_pass(t, 2 * kGuideTrialStartSpp - 1), TrialPass::None);
  EXPECT_EQ(guide_trial_next_pass(t, 2 * kGuideTrialStartSpp), TrialPass::Guided);
}

TEST(GuideTrial, SmallImagesJudgeTheGuideAfterMoreSamplesPerPixel) {
  EXPECT_EQ(guide_trial_mature_spp(240 * 240), kGuideTrialStartSpp);
  EXPECT_EQ(guide_trial_mature_spp(128 * 128), 32u);
  EXPECT_EQ(guide_trial_mature_spp(40 * 30), kGuideTrialMatureSppCap);
  EXPECT_EQ(guide_trial_mature_spp(0), kGuideTrialMatureSppCap);
}

// Synthetic trial passes: per pixel, `spp` samples of mean 1 and relative
// standard deviation `rel_sd` (Gaussian), and in `outliers` pixels one sample
// of `outlier` instead: the heavy samples of a young guide.
Film synthetic_pass(const Film& before, uint32_t spp, double rel_sd, int outliers, double outlier, std::mt19937_64& rng) {
  Film f = before;
  std::normal_distribution<double> normal(1.0, rel_sd);
  std::vector<char> heavy(f.pixels.size(), 0);
  std::uniform_int_distribution<size_t> pick(0, f.pixels.size() - 1);
  for (int k = 0; k < outliers; ++k) heavy[pick(rng)] = 1;
  for (size_t i = 0; i < f.pixels.size(); ++i) {
    PixelAccum& p = f.pixels[i];
    for (uint32_t k = 0; k < spp; ++k) {
      const double x = heavy[i] && k == 0 ? outlier : normal(rng);
      for (int c = 0; c < 3; ++c) {
        p.sum[c] += x;
        p.sum_sq[c] += x * x;
      }
    }
    p.n += spp;
  }
  return f;
}

struct SyntheticWindow {
  double guided_sd, unguided_sd;
  int guided_outliers;
  double outlier;
};

// Runs trial windows on a 64x64 film: guided and unguided passes of 8 spp
// and 1000 ray queries each until the trial decides; returns the trial, and
// the plain mean over pixels of the first window's relative variances (what
// the trial measured before) in `plain`.
GuideTrial synthetic_trial(const SyntheticWindow& w, double plain[2]) {
  GuideTrial t;
  guide_trial_start(t, 64 * 64);
  std::mt19937_64 rng(7);
  Film f(64, 64);
  f = synthetic_pass(f, kGuideTrialStartSpp, w.unguided_sd, 0, 0.0, rng);
  uint32_t index = kGuideTrialStartSpp;
  plain[0] = plain[1] = 0.0;
  while (t.state == GuideTrialState::Pending && index < 4096) {
    const TrialPass p = guide_trial_next_pass(t, index);
    const bool guided = p == TrialPass::Guided || (p == TrialPass::None && guide_trial_guiding(t));
    Film g = guided ? synthetic_pass(f, 8, w.guided_sd, w.guided_outliers, w.outlier, rng)
                    : synthetic_pass(f, 8, w.unguided_sd, 0, 0.0, rng);
    if (p != TrialPass::None && t.windows_done == 0) {
      double groups[kGuideTrialGroups];
      guide_trial_pass_estimates(g, f.pixels, groups);
      double mean = 0.0;
      for (double v : groups) mean += v / kGuideTrialGroups;  // groups of equal size, about
      plain[guided ? 1 : 0] += mean / kGuideTrialPassesPerMethod;
    }
    guide_trial_record(t, p != TrialPass::None, guided, g, f.pixels, 8, 64 * 64 * 8, 1000);
    f = std::move(g);
    index += 8;
  }
  return t;
}

// A guide whose samples have a quarter of the unguided variance, but whose
// passes each hold six samples 10^4 times the mean (a young guide's
// fireflies): the plain mean over pixels puts it far behind; the median over
// pixel groups sees the typical pixel, keeps the guide, and judges it mature
// windows later the same way.
TEST(GuideTrialEstimator, AFewHugeOutliersDoNotFlipTheDecision) {
  double plain[2];
  const GuideTrial t = synthetic_trial({0.2, 0.4, 6, 1e4}, plain);
  EXPECT_GT(plain[1] * kGuidedQueryCost, plain[0]) << "the outliers must put the guide behind on the plain mean";
  EXPECT_EQ(t.state, GuideTrialState::Kept);
  EXPECT_LT(t.window[0].inefficiency[1], t.window[0].inefficiency[0]);
  EXPECT_NEAR(t.window[0].rel_var[1] / t.window[0].rel_var[0], 0.25, 0.05);
  // The unguided samples, four times as noisy per sample, left the image.
  EXPECT_EQ(t.dropped_method, 0);
}

// A method genuinely worse everywhere is rejected, and its samples, four
// times as noisy, leave the image.
TEST(GuideTrialEstimator, AGenuinelyWorseMethodIsRejected) {
  double plain[2];
  const GuideTrial t = synthetic_trial({1.0, 0.5, 0, 0.0}, plain);
  EXPECT_EQ(t.state, GuideTrialState::SwitchedOff);
  EXPECT_EQ(t.windows_done, 2u);  // behind by more than 2x twice in a row: final at the second window
  EXPECT_EQ(t.dropped_method, 1);
  EXPECT_EQ(t.dropped_spp, 2 * kGuideTrialPassesPerMethod * 8);  // both windows' guided passes
  // Worse only by its cost (equal noise): rejected, but its samples stay.
  const GuideTrial c = synthetic_trial({0.5, 0.5, 0, 0.0}, plain);
  EXPECT_EQ(c.state, GuideTrialState::SwitchedOff);
  EXPECT_EQ(c.dropped_method, -1);
}

// A young guide (a small image: few paths learned per spp) slightly behind
// goes on learning between windows and is judged when mature.
TEST(GuideTrial, AYoungGuideSlightlyBehindKeepsLearningUntilMature) {
  GuideTrial t;
  guide_trial_start(t, 40 * 30);
  ASSERT_EQ(t.mature_spp, kGuideTrialMatureSppCap);
  auto window = [&](double ratio) {
    t.estimates[0][0] = 1.0;
    t.estimates[1][0] = ratio / kGuidedQueryCost;
    for (int m = 0; m < 2; ++m) {
      std::fill(t.estimates[m] + 1, t.estimates[m] + kGuideTrialEstimates, t.estimates[m][0]);
      t.samples[m] = 100;
      t.queries[m] = 100.0 * (m ? kGuidedQueryCost : 1.0);
    }
    return guide_trial_decide(t);
  };
  for (double ratio : {1.5, 1.3, 1.1, 1.2}) {  // windows at 16, 32, 64, 128 spp: young
    window(ratio);
    EXPECT_EQ(t.state, GuideTrialState::Pending);
    EXPECT_TRUE(guide_trial_guiding(t));
  }
  window(0.6);  // at 256 spp: mature, but the window before disagrees
  EXPECT_EQ(t.state, GuideTrialState::Pending);
  window(0.5);  // the second mature window decides
  EXPECT_EQ(t.state, GuideTrialState::Kept);
  EXPECT_EQ(t.windows_done, 6u);
}

RenderOptions trial_options(uint32_t spp) {
  RenderOptions opt;
  opt.guide_trial = true;
  opt.spp = spp;
  return opt;
}

// A plane under a quad light, nothing else: next-event estimation gets all
// the light there is, the guide can only add cost.
SceneDesc direct_light_only() {
  return load_pbrt_string(R"(
LookAt 0 0 -5  0 0 0  0 1 0
Camera "perspective" "float fov" [ 30 ]
Film "rgb" "integer xresolution" [ 24 ] "integer yresolution" [ 24 ]
Sampler "independent" "integer pixelsamples" [ 320 ]
Integrator "path" "integer maxdepth" [ 5 ]
WorldBegin
AttributeBegin
AreaLightSource "diffuse" "rgb L" [ 4 4 4 ]
Shape "trianglemesh" "point3 P" [ 2 -1 -3  4 -1 -3  4 1 -3  2 1 -3 ] "integer indices" [ 0 1 2 0 2 3 ]
AttributeEnd
Material "diffuse" "rgb reflectance" [ 0.5 0.5 0.5 ]
Shape "trianglemesh" "point3 P" [ -10 -10 0  10 -10 0  10 10 0  -10 10 0 ] "integer indices" [ 0 2 1 0 3 2 ]
)",
                          "<direct>", ".");
}

TEST(GuideTrial, SwitchesGuidingOffWhereItCannotPayAndStaysUnbiased) {
  GuidedScene s(direct_light_only());
  GuideField guide = s.make_guide();
  RenderResult g = s.run(&guide, trial_options(320));
  EXPECT_EQ(g.stats.guide_trial.state, GuideTrialState::SwitchedOff);
  EXPECT_GT(g.stats.guide_trial.inefficiency[1], g.stats.guide_trial.inefficiency[0]);
  EXPECT_EQ(g.stats.pass_stats.back().guided_samples, 0u);  // after the decision no path is guided
  EXPECT_EQ(g.stats.spp, 320u);
  for (const PixelAccum& p : g.film.pixels) ASSERT_EQ(p.n, 320u);
  RenderResult u = s.run(nullptr, testing::seeded(1000003));
  testing::expect_precise(channel_stats(u.film), 0.01, "direct light");
  testing::expect_agree(channel_stats(g.film), channel_stats(u.film), "direct light with the trial");
}

TEST(GuideTrial, KeepsGuidingWhereItPaysAndTheImageMatchesUnguided) {
  // 64x48: 32 spp train the guide too little to judge it (at 40x30 the
  // trial before this one switched it off on every seed); it is judged
  // mature from 256 spp.
  GuidedScene s(testing::shipped("door-ajar", 64, 48, 544, 8));
  GuideField guide = s.make_guide();
  RenderResult g = s.run(&guide, trial_options(544));
  EXPECT_EQ(g.stats.guide_trial.state, GuideTrialState::Kept);
  EXPECT_GE(g.stats.guide_trial.windows_done, 4u);
  EXPECT_LT(g.stats.guide_trial.inefficiency[1], g.stats.guide_trial.inefficiency[0]);
  RenderResult u = s.run(nullptr, testing::seeded(1000003));
  testing::expect_agree(channel_stats(g.film), channel_stats(u.film), "door-ajar with the trial");
}

// The closed emitting sphere of albedo 1 at depth 1000: unguided samples are
// all about 1001, guided ones scatter widely (a relative variance per sample
// thousands of times higher). The trial switches the guide off after two
// windows, takes every guided sample out of the image and renders them again
// unguided: the image holds no guided sample.
TEST(GuideTrial, DepthThousandFurnaceKeepsNoGuidedSample) {
  GuidedScene s(load_pbrt_string(testing::furnace_scene(1.0, 1000, 8, 128), "<furnace>", "."));
  GuideField guide = s.make_guide();
  RenderResult g = s.run(&guide, trial_options(128));
  const GuideTrial& t = g.stats.guide_trial;
  EXPECT_EQ(t.state, GuideTrialState::SwitchedOff);
  EXPECT_EQ(t.windows_done, 2u);
  EXPECT_EQ(t.dropped_method, 1);
  EXPECT_EQ(t.dropped_spp, kGuideTrialStartSpp + 2 * kGuideTrialPassesPerMethod * 8);
  EXPECT_EQ(g.stats.spp, 128u);
  for (const PixelAccum& p : g.film.pixels) ASSERT_EQ(p.n, 128u);
  // The 32 guided spp kept would leave a relMSE of about 32 x 2.6 / 128^2 = 5e-3
  // (t.window[1].rel_var[1]); unguided samples are all but exact (a rare one
  // differs: the sphere is tessellated).
  EXPECT_GT(t.window[1].rel_var[1], 1.0);
  const ErrorEstimate eg = estimate_rel_mse(g.film);
  ASSERT_TRUE(eg.valid);
  EXPECT_LT(eg.rel_mse, 1e-6);
  EXPECT_NEAR(channel_stats(g.film).mean[0], 1001.0, 1.0);
}

TEST(GuideTrial, SameSeedGivesTheSameImageAndDecisionForAnyThreadCount) {
  GuidedScene s(testing::shipped("door-ajar", 24, 18, 104, 8));
  RenderOptions one = trial_options(104), three = trial_options(104);
  one.threads = 1;
  three.threads = 3;
  GuideField g1 = s.make_guide(), g3 = s.make_guide();
  RenderResult a = s.run(&g1, one), b = s.run(&g3, three);
  EXPECT_TRUE(testing::films_identical(a.film, b.film));
  EXPECT_EQ(a.stats.guide_trial.state, b.stats.guide_trial.state);
  EXPECT_EQ(a.stats.guide_trial.windows_done, b.stats.guide_trial.windows_done);
  EXPECT_TRUE(g1 == g3);
}

// Stopped in the middle of a window, with the guide tentatively off and an
// unguided part kept apart, and resumed from its checkpoint: the decision,
// the samples it takes out and the image are those of an uninterrupted render.
TEST(GuideTrial, ResumedRenderEqualsTheUninterruptedOne) {
  GuidedScene f(load_pbrt_string(testing::furnace_scene(0.95, 200, 8, 128), "<furnace>", "."));
  RenderOptions opt = trial_options(128);
  opt.progress = false;
  opt.max_depth = 200;
  GuideField whole_guide = f.make_guide();
  const RenderResult whole = render(f.scene, f.embree, opt, &whole_guide);
  RenderOptions part = opt;
  part.spp = kGuideTrialStartSpp + 3 * 8;  // the first window (a guided and an unguided pass), the second's guided pass
  GuideField first_guide = f.make_guide();
  const RenderResult first = render(f.scene, f.embree, part, &first_guide);
  ASSERT_EQ(first.stats.guide_trial.state, GuideTrialState::Pending);
  ASSERT_FALSE(first.trial_unguided.empty());
  const std::string path = ::testing::TempDir() + "/trial.ckpt";
  write_checkpoint(path, first, &first_guide, f.scene.fingerprint(), 12);
  const Checkpoint ck = read_checkpoint(path, f.scene.fingerprint(), 12);
  std::istringstream gs(std::string(ck.guide.begin(), ck.guide.end()));
  std::unique_ptr<Guide> resumed_guide = load_guide(gs, f.scene.fingerprint());
  const RenderResult resumed = render(f.scene, f.embree, opt, resumed_guide.get(), &ck.so_far);
  EXPECT_EQ(resumed.stats.guide_trial.state, whole.stats.guide_trial.state);
  EXPECT_EQ(resumed.stats.guide_trial.dropped_spp, whole.stats.guide_trial.dropped_spp);
  EXPECT_TRUE(testing::films_identical(resumed.film, whole.film));
  EXPECT_TRUE(resumed_guide->same_as(whole_guide));
}

}  // namespace
}  // namespace tessera
