// Rank 0 of the farm as a PassExecutor: hands a pass's tiles out to workers
// on request (dynamic: fast ranks take more), renders tiles itself with its
// own backend meanwhile, and puts returned tiles into the film. Between
// passes it takes part in the guide's all-reduction like every rank.
#pragma once

#include <memory>
#include <set>
#include <string>

#include "comm/transport.h"
#include "render/renderer.h"

namespace tessera {

class FarmMaster : public PassExecutor {
 public:
  // Waits for every worker's Hello. `backend` (outliving the farm) renders
  // the master's own share with local_threads (>= 1) host threads; they also
  // answer the workers, between tiles.
  FarmMaster(Transport& transport, TileBackend& backend, int32_t local_threads, bool sync_guide);
  void render_pass(const TileSettings& settings, const std::vector<TileJob>& jobs, Film& film, TileCounters* counters,
                   const std::function<void(uint64_t)>& on_tile_done) override;
  void reduce_guide(std::vector<uint64_t>& accumulators) override;
  int32_t ranks() const override { return transport_.size(); }
  int32_t machines() const override { return transport_.machines(); }
  int32_t total_threads() const override { return total_threads_; }
  std::string backends() const override;
  // Whether every rank's backend computes the same bits (embree; bvh and
  // emulated-device; cuda): else the image depends on which rank rendered
  // which tile, and is reproducible only statistically.
  bool backends_agree_bitwise() const;
  // Tells the workers the render is over.
  void stop();

  double sync_seconds() const { return sync_seconds_; }
  uint64_t sync_bytes() const { return sync_bytes_; }
  uint32_t syncs() const { return syncs_; }

 private:
  Transport& transport_;
  TileBackend& backend_;
  std::set<std::string> backends_;  // of every rank
  int32_t local_threads_;
  int32_t total_threads_;
  bool sync_guide_;
  double sync_seconds_ = 0.0;
  uint64_t sync_bytes_ = 0;
  uint32_t syncs_ = 0;
};

}  // namespace tessera
