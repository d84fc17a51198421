#include "render/progress.h"

#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <cstring>

namespace tessera {

Progress::Progress(bool enabled, uint64_t total_work, double time_budget_s)
    : enabled_(enabled), tty_(isatty(fileno(stderr)) != 0), total_(total_work), budget_(time_budget_s),
      start_(std::chrono::steady_clock::now()), last_(start_) {}

void Progress::advance(uint64_t done, uint32_t spp) {
  if (!enabled_) return;
  std::unique_lock<std::mutex> lock(mutex_, std::try_to_lock);
  if (!lock.owns_lock()) return;
  auto now = std::chrono::steady_clock::now();
  double since = std::chrono::duration<double>(now - last_).count();
  if (since < (tty_ ? 0.25 : 5.0)) return;
  last_ = now;
  print(done, spp, false);
}

void Progress::finish(uint64_t done, uint32_t spp) {
  if (!enabled_) return;
  std::lock_guard<std::mutex> lock(mutex_);
  print(done, spp, true);
}

void Progress::set_error(double estimated_rel_mse, double target_error) {
  std::lock_guard<std::mutex> lock(mutex_);
  error_ = estimated_rel_mse;
  target_ = target_error;
}

void Progress::print(uint64_t done, uint32_t spp, bool final) {
  double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  double rate = elapsed > 0 ? done / elapsed : 0.0;  // samples per second
  double frac = 0.0;
  if (total_ > 0) frac = std::min(1.0, static_cast<double>(done) / total_);
  if (budget_ > 0) frac = std::max(frac, std::min(1.0, elapsed / budget_));
  // relMSE ~ 1/time: the share of the time to the target already spent is target/error.
  if (target_ > 0 && error_ > 0) frac = std::max(frac, std::min(1.0, target_ / error_));
  double eta = frac > 0 ? elapsed * (1.0 - frac) / frac : 0.0;
  char err[96] = "";
  if (error_ >= 0) std::snprintf(err, sizeof err, "  relMSE~%.3g", error_);
  // How long the requested accuracy will take, even when --time or --spp ends the render first.
  if (error_ > 0 && target_ > 0)
    std::snprintf(err + std::strlen(err), sizeof err - std::strlen(err), " (target %.3g in ~%.0fs)", target_,
                  std::max(0.0, elapsed * (error_ / target_ - 1.0)));
  char line[320];
  if (tty_) {
    constexpr int kWidth = 30;
    int filled = static_cast<int>(frac * kWidth);
    std::string bar(filled, '#');
    bar.resize(kWidth, '.');
    std::snprintf(line, sizeof line, "\r[%s] %5.1f%%  %u spp  %.2f Msamples/s  %.1fs elapsed  ETA %.1fs%s ",
                  bar.c_str(), 100 * frac, spp, rate * 1e-6, elapsed, final ? 0.0 : eta, err);
    std::fputs(line, stderr);
    if (final) std::fputc('\n', stderr);
  } else {
    std::snprintf(line, sizeof line, "progress: %5.1f%%  %u spp  %.2f Msamples/s  %.1fs elapsed  ETA %.1fs%s\n",
                  100 * frac, spp, rate * 1e-6, elapsed, final ? 0.0 : eta, err);
    std::fputs(line, stderr);
  }
  std::fflush(stderr);
}

}  // namespace tessera
