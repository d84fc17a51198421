// Intermediate images written while a render runs (--snapshot-every), so a
// convergence curve — error versus time — can be measured from one render.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "render/image_output.h"

namespace tessera {

struct RenderResult;  // render/renderer.h

// When to write: every `every_s` seconds, or each time the samples per
// pixel reach the next power of two (evenly spaced on a log-log plot).
// Snapshots are taken at pass ends, where the film holds whole passes.
struct SnapshotPolicy {
  double every_s = 0.0;
  bool doubling = false;
  bool enabled() const { return every_s > 0 || doubling; }
};

// "SECONDS" (a positive number) or "doubling"; throws naming --snapshot-every.
SnapshotPolicy parse_snapshot_policy(const std::string& text);

struct SnapshotRecord {
  std::string file;
  uint32_t spp = 0;
  double seconds = 0.0;         // wall clock since the render started
  double render_seconds = 0.0;  // the same without time spent writing snapshots and checkpoints
  double estimated_rel_mse = -1.0;
};

// Writes <dir>/<stem>-snapshots/<stem>-<spp>spp.exr (mean + variance, with
// the render's metadata) and appends a line per snapshot to snapshots.csv
// there, so an interrupted render keeps its record too. A fresh render
// first removes the snapshots of an earlier one of the same output; a
// resumed render (`resumed`) continues its record.
class SnapshotWriter {
 public:
  SnapshotWriter(SnapshotPolicy policy, const std::string& output_exr, ExrMetadata base, bool resumed = false);
  // Called after every pass; writes a snapshot when one is due.
  void on_pass_end(const RenderResult& so_far);
  const std::vector<SnapshotRecord>& records() const { return records_; }
  const std::string& directory() const { return dir_; }

 private:
  SnapshotPolicy policy_;
  std::string dir_, stem_;
  ExrMetadata base_;
  double last_s_ = 0.0;
  uint64_t next_spp_ = 1;
  std::vector<SnapshotRecord> records_;
};

}  // namespace tessera
