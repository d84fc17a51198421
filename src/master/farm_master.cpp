#include "master/farm_master.h"

#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <atomic>
#include <cstring>
#include <chrono>
#include <exception>
#include <mutex>
#include <thread>

#include "comm/farm_protocol.h"
#include "master/interrupt.h"
#include "master/ordered_splats.h"
#include "worker/thread_guide_accumulators.h"

namespace tessera {
namespace {

TileWork tile_work(const TileJob& job, const Film& film) {
  TileWork w{job, {}, {}};
  w.pixels.reserve(static_cast<size_t>(job.x1 - job.x0) * (job.y1 - job.y0));
  for (int32_t y = job.y0; y < job.y1; ++y)
    for (int32_t x = job.x0; x < job.x1; ++x) w.pixels.push_back(film.at(x, y));
  return w;
}

uint64_t job_samples(const TileJob& j) {
  return static_cast<uint64_t>(j.x1 - j.x0) * (j.y1 - j.y0) * (j.sample_end - j.sample_begin);
}

}  // namespace

FarmMaster::FarmMaster(Transport& transport, const EmbreeScene& embree, const SceneView& view, int32_t local_threads,
                       bool sync_guide)
    : transport_(transport),
      tracer_(embree.tracer()),
      view_(view),
      local_threads_(local_threads),
      total_threads_(local_threads),
      sync_guide_(sync_guide) {
  for (int32_t r = 1; r < transport_.size(); ++r) {
    Message m = transport_.receive(r);
    if (m.tag == kTagError) throw std::runtime_error("rank " + std::to_string(r) + ": " + decode<FarmError>(m.bytes).message);
    if (m.tag != kTagHello) throw std::runtime_error("rank " + std::to_string(r) + ": unexpected message");
    total_threads_ += decode<FarmHello>(m.bytes).threads;
  }
}

void FarmMaster::render_pass(const TileSettings& settings, const std::vector<TileJob>& jobs, Film& film,
                             TileCounters* counters, const std::function<void(uint64_t)>& on_tile_done) {
  const int32_t workers = transport_.size() - 1;
  const FarmPassStart start{settings.specialisation, settings.path.guided_roulette};
  for (int32_t r = 1; r <= workers; ++r) transport_.send(r, kTagPassStart, encode(start));

  // One queue of tiles for the workers and the master's own threads. There
  // is no communication thread: between tiles, whichever rendering thread
  // gets the lock answers the workers (one thread in MPI at a time), so no
  // extra thread competes with rendering for the master's cores. Once the
  // queue is empty, they keep answering until every worker is done.
  std::atomic<size_t> next{0};
  std::atomic<uint32_t> empty_replies{0};
  ThreadGuideAccumulators guide_acc(settings);
  std::atomic<bool> failed{false};
  const bool light_paths = settings.path.light_traced_caustics;
  OrderedSplats splats(film, jobs.size());
  const uint32_t all_done = kRequestsInFlight * static_cast<uint32_t>(workers);
  std::mutex comm_mutex, counters_mutex;

  auto handle = [&](Message& m) {
    if (m.tag == kTagError)
      throw std::runtime_error("rank " + std::to_string(m.source) + ": " + decode<FarmError>(m.bytes).message);
    if (m.tag != kTagRequest) throw std::runtime_error("rank " + std::to_string(m.source) + ": unexpected message");
    TileRequest req = decode<TileRequest>(m.bytes);
    if (req.interrupted) note_worker_interrupt();
    for (TileWork& w : req.results) {
      // Only a job this pass handed out, as it was handed out.
      if (w.job.index >= jobs.size() || std::memcmp(&w.job, &jobs[w.job.index], sizeof(TileJob)) != 0 ||
          w.pixels.size() != static_cast<size_t>(w.job.x1 - w.job.x0) * (w.job.y1 - w.job.y0) ||
          (!light_paths && !w.splats.empty()))
        throw std::runtime_error("rank " + std::to_string(m.source) + ": malformed tile result");
      const TileJob& j = jobs[w.job.index];
      size_t k = 0;
      for (int32_t y = j.y0; y < j.y1; ++y)
        for (int32_t x = j.x0; x < j.x1; ++x) film.at(x, y) = w.pixels[k++];
      if (light_paths) splats.add(j.index, std::move(w.splats), job_light_paths(settings, j));
      if (on_tile_done) on_tile_done(job_samples(j));
    }
    {
      std::lock_guard<std::mutex> lock(counters_mutex);
      counters->add(req.counters);
    }
    TileJobs reply;
    for (uint32_t k = 0; k < req.capacity; ++k) {
      const size_t i = next.fetch_add(1);
      if (i >= jobs.size()) break;
      reply.jobs.push_back(tile_work(jobs[i], film));
    }
    if (reply.jobs.empty()) ++empty_replies;
    transport_.send(m.source, kTagJobs, encode(reply));
  };
  auto serve = [&] {
    std::unique_lock<std::mutex> lock(comm_mutex, std::try_to_lock);
    if (!lock) return;
    Message m;
    while (transport_.try_receive(&m, -1)) handle(m);
  };

  tbb::task_arena arena(local_threads_);
  try {
    arena.execute([&] {
      tbb::parallel_for(0, local_threads_, [&](int32_t) {
        try {
          while (!failed) {
            serve();
            const size_t i = next.fetch_add(1);  // one tile at a time, so the workers find the rest
            if (i >= jobs.size()) break;
            std::vector<Splat> tile_splats;
            TileCounters tc = render_tile(view_, tracer_, guide_acc.for_this_thread(), jobs[i], film_tile(film, jobs[i]),
                                          light_paths ? &tile_splats : nullptr);
            if (light_paths) splats.add(jobs[i].index, std::move(tile_splats), job_light_paths(settings, jobs[i]));
            {
              std::lock_guard<std::mutex> lock(counters_mutex);
              counters->add(tc);
            }
            if (on_tile_done) on_tile_done(tc.samples);
          }
          while (!failed && empty_replies < all_done) {
            serve();
            std::this_thread::sleep_for(std::chrono::microseconds(50));
          }
        } catch (...) {
          failed = true;
          throw;
        }
      });
    });
  } catch (...) {
    failed = true;
    throw;
  }
  if (light_paths) splats.finish();
  guide_acc.gather();
}

void FarmMaster::reduce_guide(GuideField& guide) {
  if (!sync_guide_ || transport_.size() == 1) return;
  const auto t0 = std::chrono::steady_clock::now();
  transport_.allreduce_sum(guide.accumulators());
  sync_seconds_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  sync_bytes_ = guide.accumulators().size() * sizeof(uint64_t);
  ++syncs_;
}

void FarmMaster::stop() {
  for (int32_t r = 1; r < transport_.size(); ++r) transport_.send(r, kTagStop, encode(FarmEmpty{}));
}

}  // namespace tessera
