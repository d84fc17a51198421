#include "worker/farm_worker.h"

#include <atomic>
#include <chrono>
#include <cstdio>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "comm/farm_protocol.h"
#include "comm/guide_wire.h"
#include "render/guide_binding.h"
#include "render/interrupt.h"

namespace tessera {
namespace {

// A batch of tiles the master sent, each into its own pixel buffer.
class BatchQueue : public TileQueue {
 public:
  explicit BatchQueue(std::vector<TileWork>& work) : work_(work) {}
  bool take(TileTask* task) override {
    const size_t i = next_.fetch_add(1);
    if (i >= work_.size()) return false;
    TileWork& w = work_[i];
    *task = TileTask{w.job, TilePixels{w.pixels.data(), w.job.x1 - w.job.x0}, i};
    return true;
  }
  void done(const TileTask& task, uint64_t, std::vector<Splat>&& splats) override {
    work_[task.slot].splats = std::move(splats);
  }

 private:
  std::vector<TileWork>& work_;
  std::atomic<size_t> next_{0};
};

// Thrown inside a pass when a later pass began or the render ended: the
// master left this worker out of the pass under way.
struct LeftBehind {};

class FarmWorker {
 public:
  FarmWorker(Transport& t, TileBackend& backend, const TileSettings& settings, std::unique_ptr<Guide>& guide,
             const FarmWorkerOptions& options)
      : t_(t), backend_(backend), base_(settings), guide_(guide), options_(options),
        // Enough tiles per request for every thread (or the device), few
        // enough that the end of a pass stays balanced.
        capacity_(backend.tiles_per_request(options.threads)) {}

  // Passes until the master says stop.
  void run() {
    for (;;) {
      Message m = next();
      if (m.tag == kTagStop) break;
      if (m.tag == kTagPassStart) run_pass(decode<FarmPassStart>(m.bytes));
      // Anything else is about a pass it was left out of.
    }
    t_.send(0, kTagBye, {});
    pause("bye");
  }

  // After a failure: the master reports it and ends the job (MPI_Abort);
  // until then, or until it says stop (in-process farms), nothing more.
  void wait_for_stop() {
    while (next().tag != kTagStop) {
    }
    t_.send(0, kTagBye, {});
  }

 private:
  void pause(const char* point) {
    if (options_.pause) options_.pause(point);
  }
  Message next();
  void run_pass(const FarmPassStart& start);
  void render_share(uint32_t pass);
  void render_batch(uint32_t pass, TileJobs& jobs);
  void combine(uint32_t pass);
  void await(Message* m, uint32_t pass, int32_t tag);

  Transport& t_;
  TileBackend& backend_;
  const TileSettings& base_;
  std::unique_ptr<Guide>& guide_;
  const FarmWorkerOptions& options_;
  const uint32_t capacity_;
  std::optional<Message> pending_;  // a pass start or stop that came while a pass was under way
  std::chrono::steady_clock::time_point heard_ = std::chrono::steady_clock::now();
};

// The next message from the master. While it waits, it asks after the
// master every quarter of the timeout; a master that answers nothing for the
// whole timeout is gone.
Message FarmWorker::next() {
  if (pending_) {
    Message m = std::move(*pending_);
    pending_.reset();
    return m;
  }
  using Clock = std::chrono::steady_clock;
  const Clock::time_point start = Clock::now();
  for (;;) {
    Message m;
    if (t_.receive_within(&m, 0, options_.timeout_s / 4)) {
      heard_ = Clock::now();
      if (m.tag == kTagPong) continue;
      return m;
    }
    const double silent = std::chrono::duration<double>(Clock::now() - std::max(start, heard_)).count();
    if (silent >= options_.timeout_s) {
      char what[200];
      std::snprintf(what, sizeof what, "rank 0 (the master) silent for %.0f s (--farm-timeout); the job cannot go on without it",
                    silent);
      throw MasterSilent(what);
    }
    t_.send(0, kTagPing, {});
  }
}

void FarmWorker::run_pass(const FarmPassStart& start) {
  if (!start.guide.empty()) guide_ = guide_from_bytes(start.guide, options_.scene_fingerprint);
  TileSettings settings = base_;
  settings.specialisation = start.specialisation;
  settings.path.guided_roulette = start.guided_roulette;
  const bool guided = guide_ && (start.specialisation & kSpecGuiding) != 0;
  // An unguided pass (the --guide auto trial's, or after it switched
  // guiding off) gets no view at all: the last guided pass's view points
  // into accumulators that folding may have reallocated since.
  settings.path.guide = GuideView{};
  settings.path.neural = NeuralGuideView{};
  settings.neural_log = nullptr;
  if (guided) bind_guide(*guide_, &settings);
  backend_.begin_pass(settings);
  try {
    render_share(start.pass);
  } catch (const LeftBehind&) {
    backend_.end_pass();
    return;  // its learning of this pass goes nowhere: the next pass brings the master's guide
  }
  backend_.end_pass();
  if (!guided) return;
  try {
    combine(start.pass);
  } catch (const LeftBehind&) {
  }
}

// A pass's share of tiles: keeps kRequestsInFlight requests open, so the
// next tiles are already here when the current ones are done.
void FarmWorker::render_share(uint32_t pass) {
  for (uint32_t k = 0; k < kRequestsInFlight; ++k)
    t_.send(0, kTagRequest, encode(TileRequest{pass, capacity_, {}, {}, interrupt_requested()}));
  uint32_t open = kRequestsInFlight;
  while (open > 0) {
    Message m;
    await(&m, pass, kTagJobs);
    TileJobs jobs = decode<TileJobs>(m.bytes);
    if (jobs.pass != pass) continue;  // an answer from a pass it was left out of
    --open;
    if (jobs.jobs.empty()) continue;  // none left in this pass (later replies say the same)
    render_batch(pass, jobs);
    ++open;
  }
}

void FarmWorker::render_batch(uint32_t pass, TileJobs& jobs) {
  for (const TileWork& w : jobs.jobs)
    if (w.pixels.size() != static_cast<size_t>(w.job.x1 - w.job.x0) * (w.job.y1 - w.job.y0))
      throw std::runtime_error("malformed tile job");
  pause("tiles");
  BatchQueue queue(jobs.jobs);
  TileRequest req{pass, capacity_, {}, {}};
  req.counters = WireCounters::to_wire(backend_.render_tiles(queue, options_.threads));
  req.results = std::move(jobs.jobs);
  req.interrupted = interrupt_requested();  // signalled: the master stops the farm after this pass
  t_.send(0, kTagRequest, encode(req));
  pause("result");
}

// Each round: its accumulators to the master, the sum of every rank's back.
void FarmWorker::combine(uint32_t pass) {
  if (!options_.sync_guide) {
    combine_guide_rounds(*guide_, [](std::vector<uint64_t>&) {});
    return;
  }
  uint32_t round = 0;
  combine_guide_rounds(*guide_, [&](std::vector<uint64_t>& acc) {
    pause("round");
    t_.send(0, kTagRound, encode(GuideRound{pass, round, acc}));
    for (;;) {
      Message m;
      await(&m, pass, kTagRound);
      GuideRound sum = decode<GuideRound>(m.bytes);
      if (sum.pass != pass || sum.round != round) continue;  // from a pass it was left out of
      if (sum.words.size() != acc.size()) throw std::runtime_error("malformed guide round");
      acc = std::move(sum.words);
      break;
    }
    ++round;
  });
}

// The next message of kind `tag`; others about old passes are dropped. A
// pass start or stop means the master went on without this worker.
void FarmWorker::await(Message* m, uint32_t pass, int32_t tag) {
  for (;;) {
    *m = next();
    if (m->tag == tag) return;
    if (m->tag == kTagPassStart || m->tag == kTagStop) {
      pending_ = std::move(*m);
      throw LeftBehind{};
    }
    if (m->tag != kTagJobs && m->tag != kTagRound)
      throw std::runtime_error("unexpected message from the master in pass " + std::to_string(pass));
  }
}

}  // namespace

void run_farm_worker(Transport& t, TileBackend& backend, const TileSettings& settings, std::unique_ptr<Guide>& guide,
                     const FarmWorkerOptions& options) {
  FarmWorker worker(t, backend, settings, guide, options);
  t.send(0, kTagHello, encode(FarmHello{options.threads, backend.name()}));
  try {
    worker.run();
  } catch (const MasterSilent&) {
    throw;
  } catch (const std::exception& e) {
    t.send(0, kTagError, encode(FarmError{e.what()}));
    worker.wait_for_stop();
  }
}

}  // namespace tessera
