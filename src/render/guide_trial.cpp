#include "render/guide_trial.h"

#include <algorithm>
#include <cmath>

#include "render/image_metrics.h"

namespace tessera {

TrialPass guide_trial_next_pass(const GuideTrial& t, uint32_t spp_done) {
  if (t.state != GuideTrialState::Pending || spp_done < kGuideTrialStartSpp) return TrialPass::None;
  return t.passes[1] <= t.passes[0] ? TrialPass::Guided : TrialPass::Unguided;
}

void guide_trial_record(GuideTrial& t, bool guided, const Film& film, const std::vector<PixelAccum>& before,
                        uint64_t samples, uint64_t queries) {
  // Relative variance of one sample of this pass, against the image so far
  // (its mean is the least noisy denominator both methods share).
  double sum = 0.0, pass_n = 0.0;
  for (size_t i = 0; i < film.pixels.size(); ++i) {
    const PixelAccum& now = film.pixels[i];
    const PixelAccum& was = before[i];
    const double n = static_cast<double>(now.n - was.n);
    if (n < 2) continue;
    pass_n = n;
    for (int c = 0; c < 3; ++c) {
      const double s = now.sum[c] - was.sum[c], s2 = now.sum_sq[c] - was.sum_sq[c];
      const double var = std::max(0.0, (s2 - s * s / n) / (n - 1.0));
      const double mean = now.sum[c] / static_cast<double>(now.n);
      sum += var / (mean * mean + kRelMseEpsilon);
    }
  }
  const int m = guided ? 1 : 0;
  const double rel_var = film.pixels.empty() ? 0.0 : sum / (3.0 * static_cast<double>(film.pixels.size()));
  if (pass_n >= 2 && std::isfinite(rel_var)) {
    t.rel_var_samples[m] += rel_var * static_cast<double>(samples);
    t.samples[m] += samples;
    t.cost[m] += static_cast<double>(queries) * (guided ? kGuidedQueryCost : 1.0);
  }
  ++t.passes[m];
  if (t.passes[0] < kGuideTrialPassesPerMethod || t.passes[1] < kGuideTrialPassesPerMethod) return;
  for (int k = 0; k < 2; ++k) {
    const double n = static_cast<double>(std::max<uint64_t>(1, t.samples[k]));
    t.inefficiency[k] = (t.rel_var_samples[k] / n) * (t.cost[k] / n);
  }
  // The cheaper per unit of error goes on; a tie (no noise at all) goes to the cheaper per sample.
  const bool measured = t.samples[0] > 0 && t.samples[1] > 0;
  const bool costs = t.inefficiency[1] > t.inefficiency[0] ||
                     (t.inefficiency[1] == t.inefficiency[0] &&
                      t.cost[1] / static_cast<double>(std::max<uint64_t>(1, t.samples[1])) >
                          t.cost[0] / static_cast<double>(std::max<uint64_t>(1, t.samples[0])));
  t.state = measured && costs ? GuideTrialState::SwitchedOff : GuideTrialState::Kept;
}

}  // namespace tessera
