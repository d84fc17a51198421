#include "worker/farm_worker.h"

#include <atomic>
#include <utility>
#include <vector>

#include "comm/farm_protocol.h"
#include "render/interrupt.h"
#include "render/guide_binding.h"

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

// Renders a pass's share of tiles: keeps kRequestsInFlight requests open, so
// the next tiles are already here when the current ones are done.
void render_pass_tiles(Transport& t, TileBackend& backend, int32_t threads, uint32_t capacity) {
  for (uint32_t k = 0; k < kRequestsInFlight; ++k)
    t.send(0, kTagRequest, encode(TileRequest{capacity, {}, {}, interrupt_requested()}));
  uint32_t open = kRequestsInFlight;
  while (open > 0) {
    Message m = t.receive(0);
    if (m.tag != kTagJobs) throw std::runtime_error("unexpected message from the master");
    --open;
    TileJobs jobs = decode<TileJobs>(m.bytes);
    if (jobs.jobs.empty()) continue;  // none left in this pass (later replies say the same)
    for (const TileWork& w : jobs.jobs)
      if (w.pixels.size() != static_cast<size_t>(w.job.x1 - w.job.x0) * (w.job.y1 - w.job.y0))
        throw std::runtime_error("malformed tile job");
    BatchQueue queue(jobs.jobs);
    TileRequest req{capacity, {}, {}};
    req.counters = WireCounters::to_wire(backend.render_tiles(queue, threads));
    req.results = std::move(jobs.jobs);
    req.interrupted = interrupt_requested();  // signalled: the master stops the farm after this pass
    t.send(0, kTagRequest, encode(req));
    ++open;
  }
}

}  // namespace

void run_farm_worker(Transport& t, TileBackend& backend, const TileSettings& base, Guide* guide, bool sync_guide,
                     int32_t threads) {
  t.send(0, kTagHello, encode(FarmHello{threads, backend.name()}));
  TileSettings settings = base;
  // Enough tiles per request for every thread (or the device), few enough
  // that the end of a pass stays balanced.
  const uint32_t capacity = backend.tiles_per_request(threads);
  try {
    for (;;) {
      Message m = t.receive(0);
      if (m.tag == kTagStop) return;
      if (m.tag != kTagPassStart) throw std::runtime_error("unexpected message from the master");
      const FarmPassStart start = decode<FarmPassStart>(m.bytes);
      settings.specialisation = start.specialisation;
      settings.path.guided_roulette = start.guided_roulette;
      const bool guided = guide && (start.specialisation & kSpecGuiding) != 0;
      // An unguided pass (the --guide auto trial's, or after it switched
      // guiding off) gets no view at all: the last guided pass's view points
      // into accumulators that folding may have reallocated since.
      settings.path.guide = GuideView{};
      settings.path.neural = NeuralGuideView{};
      settings.neural_log = nullptr;
      if (guided) bind_guide(*guide, &settings);
      backend.begin_pass(settings);
      render_pass_tiles(t, backend, threads, capacity);
      backend.end_pass();
      if (guided) {
        combine_guide_rounds(*guide, [&](std::vector<uint64_t>& acc) {
          if (sync_guide) t.allreduce_sum(acc);
        });
      }
    }
  } catch (const std::exception& e) {
    // The master reports it and ends the job (MPI_Abort); until then, or
    // until it says stop (in-process farms), this rank does nothing more.
    t.send(0, kTagError, encode(FarmError{e.what()}));
    while (t.receive(0).tag != kTagStop) {
    }
  }
}

}  // namespace tessera
