// Progress reporting: a redrawn bar with rate and ETA on a terminal, a plain
// line every few seconds otherwise (logs, CI).
#pragma once

#include <chrono>
#include <cstdint>
#include <mutex>
#include <string>

namespace tessera {

class Progress {
 public:
  // total_work: units of work (samples x pixels) when known, 0 for a time budget.
  Progress(bool enabled, uint64_t total_work, double time_budget_s);
  // Thread-safe; cheap when it is not yet time to print.
  void advance(uint64_t work_done_total, uint32_t spp_done);
  void finish(uint64_t work_done_total, uint32_t spp_done);
  // After each pass: the image's estimated relMSE (< 0: not estimable yet)
  // and the --target-error (0: none). Shown beside the ETA; with a target,
  // the ETA assumes relMSE falls as 1/time, as Monte Carlo error does.
  void set_error(double estimated_rel_mse, double target_error);

 private:
  void print(uint64_t done, uint32_t spp, bool final);
  bool enabled_;
  bool tty_;
  uint64_t total_;
  double budget_;
  double error_ = -1.0, target_ = 0.0;
  std::chrono::steady_clock::time_point start_, last_;
  std::mutex mutex_;
};

}  // namespace tessera
