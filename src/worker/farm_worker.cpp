#include "worker/farm_worker.h"

#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <mutex>

#include "comm/farm_protocol.h"
#include "master/interrupt.h"
#include "worker/thread_guide_accumulators.h"

namespace tessera {
namespace {

// Renders a pass's share of tiles: keeps kRequestsInFlight requests open, so
// the next tiles are already here when the current ones are done.
void render_pass_tiles(Transport& t, const SceneView& view, const EmbreeTracer& tracer, const TileSettings& settings,
                       tbb::task_arena& arena, uint32_t capacity) {
  for (uint32_t k = 0; k < kRequestsInFlight; ++k)
    t.send(0, kTagRequest, encode(TileRequest{capacity, {}, {}, interrupt_requested()}));
  uint32_t open = kRequestsInFlight;
  std::mutex mutex;
  ThreadGuideAccumulators guide_acc(settings);
  while (open > 0) {
    Message m = t.receive(0);
    if (m.tag != kTagJobs) throw std::runtime_error("unexpected message from the master");
    --open;
    TileJobs jobs = decode<TileJobs>(m.bytes);
    if (jobs.jobs.empty()) continue;  // none left in this pass (later replies say the same)
    TileRequest req{capacity, {}, {}};
    arena.execute([&] {
      tbb::parallel_for(size_t(0), jobs.jobs.size(), [&](size_t i) {
        TileWork& w = jobs.jobs[i];
        if (w.pixels.size() != static_cast<size_t>(w.job.x1 - w.job.x0) * (w.job.y1 - w.job.y0))
          throw std::runtime_error("malformed tile job");
        w.splats.clear();
        TileCounters tc = render_tile(view, tracer, guide_acc.for_this_thread(), w.job,
                                      TilePixels{w.pixels.data(), w.job.x1 - w.job.x0},
                                      settings.path.light_traced_caustics ? &w.splats : nullptr);
        std::lock_guard<std::mutex> lock(mutex);
        req.counters.add(tc);
      });
    });
    req.results = std::move(jobs.jobs);
    req.interrupted = interrupt_requested();  // signalled: the master stops the farm after this pass
    t.send(0, kTagRequest, encode(req));
    ++open;
  }
  guide_acc.gather();
}

}  // namespace

void run_farm_worker(Transport& t, const SceneView& view, const EmbreeScene& embree, const TileSettings& base,
                     GuideField* guide, bool sync_guide, int32_t threads) {
  t.send(0, kTagHello, encode(FarmHello{threads}));
  const EmbreeTracer tracer = embree.tracer();
  tbb::task_arena arena(threads);
  TileSettings settings = base;
  // Enough tiles per request for every thread, at most a few per thread so
  // the end of a pass stays balanced.
  const uint32_t capacity = static_cast<uint32_t>(threads);
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
      settings.path.guide = guided ? guide->view() : GuideView{};
      render_pass_tiles(t, view, tracer, settings, arena, capacity);
      if (guided) {
        if (sync_guide) t.allreduce_sum(guide->accumulators());
        guide->fold();
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
