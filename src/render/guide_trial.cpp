#include "render/guide_trial.h"

#include <algorithm>
#include <cmath>

#include "render/image_metrics.h"

namespace tessera {
namespace {

// Interleaved groups: a multiplicative hash of the pixel index, so that each
// group samples the whole image (bright and dark parts alike) and the groups'
// means estimate the same quantity.
uint32_t pixel_group(size_t i) {
  return static_cast<uint32_t>((static_cast<uint64_t>(i) * 0x9E3779B97F4A7C15ull) >> 40) % kGuideTrialGroups;
}

// Guided inefficiency over unguided; with no noise at all, the cost ratio.
double window_ratio(const GuideTrialWindow& w) {
  if (w.inefficiency[0] > 0) return w.inefficiency[1] / w.inefficiency[0];
  if (w.inefficiency[1] > 0) return 1e30;
  return w.cost[0] > 0 ? w.cost[1] / w.cost[0] : 1.0;
}

}  // namespace

uint32_t guide_trial_mature_spp(uint64_t pixels) {
  const uint64_t spp = (kGuideTrialMatureSamples + std::max<uint64_t>(1, pixels) - 1) / std::max<uint64_t>(1, pixels);
  return static_cast<uint32_t>(std::clamp<uint64_t>(spp, kGuideTrialStartSpp, kGuideTrialMatureSppCap));
}

void guide_trial_start(GuideTrial& t, uint64_t pixels) {
  t = GuideTrial{};
  t.state = GuideTrialState::Pending;
  t.mature_spp = guide_trial_mature_spp(pixels);
}

TrialPass guide_trial_next_pass(const GuideTrial& t, uint32_t sample_index) {
  if (t.state != GuideTrialState::Pending || t.windows_done >= kGuideTrialWindows) return TrialPass::None;
  if (sample_index < (kGuideTrialStartSpp << t.windows_done)) return TrialPass::None;
  return t.passes[1] <= t.passes[0] ? TrialPass::Guided : TrialPass::Unguided;
}

bool guide_trial_guiding(const GuideTrial& t) {
  switch (t.state) {
    case GuideTrialState::Pending: return t.guiding != 0;
    case GuideTrialState::SwitchedOff: return false;
    default: return true;
  }
}

double guide_trial_median(const double* estimates, uint32_t n) {
  std::vector<double> v;
  for (uint32_t i = 0; i < n; ++i)
    if (estimates[i] >= 0 && std::isfinite(estimates[i])) v.push_back(estimates[i]);
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  const size_t h = v.size() / 2;
  return v.size() % 2 ? v[h] : 0.5 * (v[h - 1] + v[h]);
}

void guide_trial_pass_estimates(const Film& film, const std::vector<PixelAccum>& before, double* groups) {
  double sum[kGuideTrialGroups] = {}, count[kGuideTrialGroups] = {};
  for (size_t i = 0; i < film.pixels.size(); ++i) {
    const PixelAccum& now = film.pixels[i];
    const PixelAccum& was = before[i];
    const double n = static_cast<double>(now.n - was.n);
    if (n < 2) continue;
    // Relative variance of one sample of this pass, against the image so far
    // (its mean is the least noisy denominator both methods share).
    double r = 0.0;
    for (int c = 0; c < 3; ++c) {
      const double s = now.sum[c] - was.sum[c], s2 = now.sum_sq[c] - was.sum_sq[c];
      const double var = std::max(0.0, (s2 - s * s / n) / (n - 1.0));
      const double mean = now.sum[c] / static_cast<double>(now.n);
      r += var / (mean * mean + kRelMseEpsilon);
    }
    const uint32_t g = pixel_group(i);
    sum[g] += r / 3.0;
    count[g] += 1.0;
  }
  for (uint32_t g = 0; g < kGuideTrialGroups; ++g) groups[g] = count[g] > 0 ? sum[g] / count[g] : -1.0;
}

int guide_trial_record(GuideTrial& t, bool trial_pass, bool guided, const Film& film,
                       const std::vector<PixelAccum>& before, uint32_t spp, uint64_t samples, uint64_t queries) {
  if (t.state != GuideTrialState::Pending) return -1;
  const int m = guided ? 1 : 0;
  t.method_spp[m] += spp;
  if (!trial_pass) return -1;
  if (t.passes[m] < kGuideTrialPassesPerMethod) {
    guide_trial_pass_estimates(film, before, &t.estimates[m][t.passes[m] * kGuideTrialGroups]);
    t.samples[m] += samples;
    t.queries[m] += static_cast<double>(queries) * (guided ? kGuidedQueryCost : 1.0);
  }
  ++t.passes[m];
  if (t.passes[0] < kGuideTrialPassesPerMethod || t.passes[1] < kGuideTrialPassesPerMethod) return -1;
  return guide_trial_decide(t);
}

int guide_trial_decide(GuideTrial& t) {
  const uint32_t k = t.windows_done;
  GuideTrialWindow& w = t.window[k];
  w.start_spp = kGuideTrialStartSpp << k;
  for (int m = 0; m < 2; ++m) {
    w.rel_var[m] = guide_trial_median(t.estimates[m], kGuideTrialEstimates);
    double sum = 0.0, n = 0.0;
    for (double e : t.estimates[m]) {
      if (!(e >= 0) || !std::isfinite(e)) continue;
      sum += e;
      n += 1.0;
    }
    w.mean_rel_var[m] = n > 0 ? sum / n : 0.0;
    w.cost[m] = t.queries[m] / static_cast<double>(std::max<uint64_t>(1, t.samples[m]));
    w.inefficiency[m] = w.rel_var[m] * w.cost[m];
    t.passes[m] = 0;
    t.queries[m] = 0;
    t.samples[m] = 0;
    std::fill(t.estimates[m], t.estimates[m] + kGuideTrialEstimates, 0.0);
  }
  t.windows_done = k + 1;
  const double ratio = window_ratio(w);
  const bool mature = w.start_spp >= t.mature_spp;
  // Tentatively: a young guide keeps learning unless it loses by 2x; a mature one by its verdict.
  t.guiding = ratio < (mature ? kGuideTrialTie : kGuideTrialEarlyMargin) ? 1u : 0u;
  bool final_now = t.windows_done >= kGuideTrialWindows || (mature && ratio < 1.0 / kGuideTrialEarlyMargin);
  if (k >= 1) {
    const double before = window_ratio(t.window[k - 1]);
    // Twice in a row far behind: off, young or not. Mature: two windows that
    // agree, or the second mature window's verdict.
    const bool far_behind = ratio > kGuideTrialEarlyMargin && before > kGuideTrialEarlyMargin;
    const bool agree = (ratio < kGuideTrialTie) == (before < kGuideTrialTie);
    const bool second_mature = t.window[k - 1].start_spp >= t.mature_spp;
    final_now = final_now || far_behind || (mature && (agree || second_mature));
  }
  if (!final_now) return -1;
  t.guiding = ratio < kGuideTrialTie ? 1u : 0u;
  t.state = t.guiding ? GuideTrialState::Kept : GuideTrialState::SwitchedOff;
  t.inefficiency[0] = w.inefficiency[0];
  t.inefficiency[1] = w.inefficiency[1];
  // The loser's samples so far leave the image where they are much noisier than the winner's.
  const int loser = t.guiding ? 0 : 1;
  const bool noisier = (w.rel_var[loser] >= kGuideTrialDropRatio * w.rel_var[1 - loser] && w.rel_var[loser] > 0) ||
                       (w.mean_rel_var[loser] >= kGuideTrialDropRatio * w.mean_rel_var[1 - loser] && w.mean_rel_var[loser] > 0);
  if (!noisier || t.method_spp[loser] == 0) return -1;
  t.dropped_method = loser;
  t.dropped_spp = t.method_spp[loser];
  return loser;
}

}  // namespace tessera
