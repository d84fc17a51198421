// Rank 0 of the farm as a PassExecutor: hands a pass's tiles out to workers
// on request (dynamic: fast ranks take more), renders tiles itself with its
// own backend meanwhile, and puts returned tiles into the film. Between
// passes it gathers each round of the guide's learning from the workers,
// adds its own, and sends every worker the sum.
//
// Liveness (docs/farm.md, "A silent rank"): a worker that owes the master
// something (a tile result, a round of learning) and sends nothing for
// `lease_s` is left out of the pass: its tiles go to the other ranks, what it
// says about that pass later is ignored, and the master renders again, for
// their learning alone, the tiles it had finished (master/stand_in.h). The
// master so never needs any one worker to finish a render. A worker left out
// takes part again from the first pass after it is heard from, with the
// master's guide; one that never says hello joins when it does.
#pragma once

#include <chrono>
#include <functional>
#include <map>
#include <memory>
#include <set>
#include <string>
#include <vector>

#include "comm/farm_protocol.h"
#include "comm/transport.h"
#include "guidecache/guide.h"
#include "master/stand_in.h"
#include "master/tile_ledger.h"
#include "render/ordered_splats.h"
#include "render/renderer.h"

namespace tessera {

struct FarmMasterOptions {
  int32_t local_threads = 1;  // the master's rendering threads (>= 1); they also answer the workers, between tiles
  bool sync_guide = true;     // --guide-sync pass
  double lease_s = 30.0;      // --farm-lease
  // The render's guide (null: none) and the scene's fingerprint: the master
  // sends a copy to a worker that missed a fold and keeps one for stand-ins.
  Guide* guide = nullptr;
  uint64_t scene_fingerprint = 0;
  // Test hook: called with "pass" as each pass begins.
  std::function<void(const char*)> pause;
};

// A worker that did not answer Stop (silent, or never started).
struct SilentRank {
  int32_t rank = 0;
  double silent_s = 0.0;  // since it was last heard from (or since the farm started)
};

class FarmMaster : public PassExecutor {
 public:
  // Waits up to the lease for every worker's Hello; the ones that have not
  // said it by then join when they do. `backend` outlives the farm.
  FarmMaster(Transport& transport, TileBackend& backend, const FarmMasterOptions& options);
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
  // Tells the workers the render is over and waits (up to the lease) for
  // their answers; returns the ones that stay silent. Under MPI the job can
  // only end without them by aborting it (cmd_render.cpp).
  std::vector<SilentRank> finish();

  double sync_seconds() const { return sync_seconds_; }
  uint64_t sync_bytes() const { return sync_bytes_; }
  uint32_t syncs() const { return syncs_; }

 private:
  using Clock = std::chrono::steady_clock;
  enum class Phase { Idle, Tiles, Rounds };
  struct Worker {
    bool joined = false;       // said hello
    bool active = false;       // takes part in the pass under way
    bool took_part = false;    // in some pass
    bool out = false;          // left out, and not heard from since
    bool stale_guide = false;  // missed a fold: its next PassStart carries the guide
    bool stopped = false;      // answered Stop
    Clock::time_point heard;   // last message, or when it began to owe one
    uint32_t empty_replies = 0;  // "none left" answers this pass
  };
  // The pass whose tiles are rendering (valid inside render_pass).
  struct PassTiles {
    const TileSettings& settings;
    const std::vector<TileJob>& jobs;
    Film& film;
    TileCounters* counters;
    const std::function<void(uint64_t)>& on_tile_done;
    OrderedSplats splats;
  };

  void join(int32_t rank, const FarmHello& hello);
  void admit_workers(const TileSettings& settings);
  void render_own_share(PassTiles& pass);
  bool tiles_finished() const;
  void serve();
  void handle(Message& m);
  void on_request(int32_t rank, TileRequest& req);
  void accept_results(int32_t rank, TileRequest& req);
  void on_round(int32_t rank, GuideRound& round);
  bool owes(int32_t rank) const;
  void check_leases();
  void leave_out(int32_t rank, double silent_s);
  void await_round();
  void add_stand_ins(uint32_t round, std::vector<uint64_t>* sum);
  const Bytes& pass_start_guide();

  Transport& transport_;
  TileBackend& backend_;
  FarmMasterOptions options_;
  std::set<std::string> backends_;  // of every rank that said hello
  int32_t total_threads_;
  std::vector<Worker> workers_;  // by rank; [0] unused
  std::mutex comm_mutex_;         // one thread in the transport at a time
  std::mutex counters_mutex_;

  // The pass under way.
  Phase phase_ = Phase::Idle;
  uint32_t pass_ = 0;
  bool pass_learns_ = false;  // a guided pass whose learning is shared
  TileSettings pass_settings_;
  std::vector<TileJob> pass_jobs_;
  std::unique_ptr<TileLedger> ledger_;
  PassTiles* tiles_ = nullptr;
  std::vector<TileJob> relearn_;  // finished tiles of workers left out while tiles render
  uint32_t round_ = 0;            // the round reduce_guide combines next
  std::map<int32_t, GuideRound> rounds_in_;  // workers' accumulators of the round awaited
  std::vector<std::pair<int32_t, std::vector<TileJob>>> stand_ins_due_;  // left out during the rounds
  std::vector<StandIn> stand_ins_;
  std::vector<std::vector<uint64_t>> round_sums_;  // this pass's, for stand-ins made in later rounds
  Bytes pass_start_guide_;                         // the guide as the pass began (made when first needed)

  double sync_seconds_ = 0.0;
  uint64_t sync_bytes_ = 0;
  uint32_t syncs_ = 0;
};

}  // namespace tessera
