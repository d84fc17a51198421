// `--guide auto`'s trial: does the guide pay on this scene?
//
// Trial windows start once the guide has learned from the first
// kGuideTrialStartSpp samples per pixel (every one of them learns: the
// default --guide-learn-spp), at sample index 16, and then at each doubling
// (32, 64, ... up to kGuideTrialWindows windows). In each
// window guided and unguided passes alternate, and each method's relative
// variance of one sample is measured from its passes' own per-pixel
// variances, robustly: the pixels fall into kGuideTrialGroups interleaved
// groups, and the figure is the median, over the window's passes and
// groups, of the groups' mean relative variance. A few heavy samples
// (fireflies of a young guide) move a group or two, not the median. That
// times the cost per sample (ray queries, a guided query weighted
// kGuidedQueryCost) is the method's inefficiency; guided / unguided is the
// window's ratio.
//
// A guide is judged at matched learning: a window counts as mature once the
// guide has learned from kGuideTrialMatureSamples paths (16 spp of 181x181
// pixels; a small image needs more spp, up to kGuideTrialMatureSppCap).
// A window's verdict is for the guide where the ratio is below
// kGuideTrialTie (a tie goes to the guide, which learns on). Between windows
// the render goes on tentatively by the verdict, except that a young guide
// goes on unless it loses by kGuideTrialEarlyMargin.
// The decision is final (guide_trial_decide) when two windows in a row put
// the guide behind by kGuideTrialEarlyMargin, or at a mature window that
// agrees with the window before, or else at the second mature window. No
// single window switches the guide off; a mature guide ahead by
// kGuideTrialEarlyMargin is kept at once (a guide that learns on only gets
// better).
//
// Samples of the losing method do not keep full weight: when the decision
// is final, the loser's passes so far (for a switched-off guide: the
// learning passes too) are taken out of the image where its measured
// relative variance per sample, robust or plain (the plain mean counts the
// fireflies the image will hold), is at least kGuideTrialDropRatio times
// the winner's: there they add more variance than their samples remove. Each
// pass is unbiased, and the weight (1 or 0) is one for the whole image,
// from medians over thousands of pixels, so a pixel's own samples move it
// negligibly; passes after the decision do not depend on it at all. The
// render then goes on until the image holds its --spp: the samples taken
// out are rendered again (new sample indices), by the winner.
//
// Cost is never counted in seconds: the decision, and so the image, depend
// only on (scene, seed, options), for any thread or rank count, and across
// a resume (the checkpoint keeps GuideTrial and the unguided part).
#pragma once

#include <cstdint>
#include <vector>

#include "render/film.h"

namespace tessera {

// Trial windows start when this many samples per pixel have trained the
// guide, and then at each doubling of the sample index.
constexpr uint32_t kGuideTrialStartSpp = 16;
// Guided and unguided passes per window, each, alternating (guided first).
constexpr uint32_t kGuideTrialPassesPerMethod = 1;
// Windows at most (at 16, 32, ... 512 spp): the last one's verdict is final.
constexpr uint32_t kGuideTrialWindows = 6;
// Paths the guide has learned from when a window counts as mature, and the
// most samples per pixel that takes.
constexpr uint64_t kGuideTrialMatureSamples = uint64_t{1} << 19;
constexpr uint32_t kGuideTrialMatureSppCap = 256;
// Interleaved pixel groups whose mean relative variances give the median.
constexpr uint32_t kGuideTrialGroups = 16;
constexpr uint32_t kGuideTrialEstimates = kGuideTrialPassesPerMethod * kGuideTrialGroups;
// Relative cost of a guided path's ray query (guide lookups, learning, the
// mixture pdf) against an unguided one.
constexpr double kGuidedQueryCost = 1.45;
// A window's verdict is for the guide below this ratio: a guide that learns
// on only gets better, so a tie goes to it (at 20 s, four of the five scenes
// whose windows measured 0.95-1.05 rendered better guided: docs/guiding.md).
constexpr double kGuideTrialTie = 1.1;
// A young guide goes on unless it loses by this factor; losing by it twice
// in a row is final.
constexpr double kGuideTrialEarlyMargin = 2.0;
// The loser's samples leave the image where their relative variance per
// sample is at least this many times the winner's: a set of n samples of
// per-sample variance r v added to N of variance v lowers the mean's
// variance only while r < 2 + n / N.
constexpr double kGuideTrialDropRatio = 2.0;

enum class GuideTrialState : uint32_t { Off = 0, Pending, Kept, SwitchedOff };

// One window's figures, per method (0 unguided, 1 guided).
struct GuideTrialWindow {
  uint32_t start_spp = 0;        // sample index at which the window started
  double rel_var[2] = {0, 0};    // robust relative variance of one sample
  double mean_rel_var[2] = {0, 0};  // the plain mean over the groups (fireflies included)
  double cost[2] = {0, 0};       // weighted ray queries per sample
  double inefficiency[2] = {0, 0};  // rel_var x cost
};

// Plain data: the checkpoint saves it as raw bytes.
struct GuideTrial {
  GuideTrialState state = GuideTrialState::Off;  // Off: no trial (not --guide auto, or unguided)
  uint32_t windows_done = 0;
  uint32_t guiding = 1;  // while Pending, between windows: 1 guided, 0 unguided (tentative)
  uint32_t mature_spp = kGuideTrialStartSpp;  // windows from this sample index judge a mature guide
  // The window under way: passes, per-(pass, group) relative variances, weighted queries, samples.
  uint32_t passes[2] = {0, 0};
  double estimates[2][kGuideTrialEstimates] = {};
  double queries[2] = {0, 0};
  uint64_t samples[2] = {0, 0};
  GuideTrialWindow window[kGuideTrialWindows] = {};
  // Samples per pixel each method rendered before the final decision, and
  // those the decision took out of the image (dropped_method: 0 unguided, 1 guided, -1 none).
  uint32_t method_spp[2] = {0, 0};
  uint32_t dropped_spp = 0;
  int32_t dropped_method = -1;
  // The final window's inefficiencies (the decision's figures).
  double inefficiency[2] = {0, 0};
};

// Samples per pixel after which the guide of an image of `pixels` counts as mature.
uint32_t guide_trial_mature_spp(uint64_t pixels);
// A pending trial for an image of `pixels`.
void guide_trial_start(GuideTrial& t, uint64_t pixels);

// What the next pass is: not part of a trial window, or a trial pass of one method.
enum class TrialPass { None, Guided, Unguided };
// `sample_index`: samples per pixel rendered so far, dropped ones included.
TrialPass guide_trial_next_pass(const GuideTrial& t, uint32_t sample_index);

// Whether a pass outside the trial windows is guided (a guide given).
bool guide_trial_guiding(const GuideTrial& t);

// The robust relative variance of one sample: median of the estimates.
double guide_trial_median(const double* estimates, uint32_t n);

// The kGuideTrialGroups mean relative variances of one sample of a pass,
// per pixel group: `before` is the film's pixels before the pass. Groups
// without a pixel of at least two samples in the pass are < 0.
void guide_trial_pass_estimates(const Film& film, const std::vector<PixelAccum>& before, double* groups);

// Records a finished pass of `spp` samples per pixel while the trial is
// pending (trial passes and those between windows), its samples and ray
// queries. Returns the method (0, 1) whose passes the final decision
// takes out of the image, or -1.
int guide_trial_record(GuideTrial& t, bool trial_pass, bool guided, const Film& film,
                       const std::vector<PixelAccum>& before, uint32_t spp, uint64_t samples, uint64_t queries);

// Decides after a window: sets t.guiding, and t.state where the decision is
// final. Returns the method to take out of the image, or -1.
int guide_trial_decide(GuideTrial& t);

}  // namespace tessera
