// `--guide auto`'s trial: once the guide has learned from the first samples,
// guided and unguided passes alternate, each pass's error per sample is
// measured from its own per-pixel variance, and the render goes on with the
// method that reaches a given error at the lower cost; the other is switched
// off. Every trial pass's samples are unbiased, so all of them stay in the
// image. Cost is counted in ray queries, a guided query weighted by what a
// guided path's bookkeeping adds (docs/guiding.md), never in wall-clock time:
// the decision, and so the image, depend only on (scene, seed, options), for
// any thread or rank count, and across a resume.
#pragma once

#include <cstdint>
#include <vector>

#include "render/film.h"

namespace tessera {

// Trial passes start when this many samples per pixel have trained the guide.
constexpr uint32_t kGuideTrialStartSpp = 32;
// Guided and unguided passes each, alternating (guided first).
constexpr uint32_t kGuideTrialPassesPerMethod = 2;
// Relative cost of a guided path's ray query (guide lookups, learning, the
// mixture pdf) against an unguided one.
constexpr double kGuidedQueryCost = 1.45;

enum class GuideTrialState : uint32_t { Off = 0, Pending, Kept, SwitchedOff };

struct GuideTrial {
  GuideTrialState state = GuideTrialState::Off;  // Off: no trial (not --guide auto, or unguided)
  // Per method (0 unguided, 1 guided): the sum over its trial passes of the
  // relative variance of one sample (mean over pixels and channels), weighted
  // by the pass's samples; the samples; the cost in weighted ray queries.
  double rel_var_samples[2] = {0, 0};
  double cost[2] = {0, 0};
  uint64_t samples[2] = {0, 0};
  uint32_t passes[2] = {0, 0};
  // The decision's figures: relative variance per sample x cost per sample.
  double inefficiency[2] = {0, 0};
};

// What the next pass is: not part of a trial, or a trial pass of one method.
enum class TrialPass { None, Guided, Unguided };
TrialPass guide_trial_next_pass(const GuideTrial& t, uint32_t spp_done);

// Records a finished trial pass: `before` is the film's pixels before it;
// its samples and ray queries. Decides when both methods have had their passes.
void guide_trial_record(GuideTrial& t, bool guided, const Film& film, const std::vector<PixelAccum>& before,
                        uint64_t samples, uint64_t queries);

}  // namespace tessera
