#include "master/farm_master.h"

#include <atomic>
#include <cstring>
#include <chrono>
#include <exception>
#include <mutex>
#include <string>
#include <utility>
#include <thread>

#include "comm/farm_protocol.h"
#include "render/interrupt.h"
#include "render/ordered_splats.h"

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

FarmMaster::FarmMaster(Transport& transport, TileBackend& backend, int32_t local_threads, bool sync_guide)
    : transport_(transport),
      backend_(backend),
      local_threads_(local_threads),
      total_threads_(local_threads),
      sync_guide_(sync_guide) {
  backends_.insert(backend.name());
  for (int32_t r = 1; r < transport_.size(); ++r) {
    Message m = transport_.receive(r);
    if (m.tag == kTagError) throw std::runtime_error("rank " + std::to_string(r) + ": " + decode<FarmError>(m.bytes).message);
    if (m.tag != kTagHello) throw std::runtime_error("rank " + std::to_string(r) + ": unexpected message");
    const FarmHello hello = decode<FarmHello>(m.bytes);
    total_threads_ += hello.threads;
    backends_.insert(hello.backend);
  }
}

bool FarmMaster::backends_agree_bitwise() const {
  std::set<std::string> families;
  for (const std::string& b : backends_) families.insert(b == "emulated-device" ? "bvh" : b);
  return families.size() <= 1;
}

std::string FarmMaster::backends() const {
  std::string all;
  for (const std::string& b : backends_) all += (all.empty() ? "" : "+") + b;
  return all;
}

namespace {

// The master's share of a pass: tiles from the one queue the workers also
// draw from, and the workers answered between tiles.
class MasterQueue : public TileQueue {
 public:
  MasterQueue(const TileSettings& settings, const std::vector<TileJob>& jobs, Film& film, std::atomic<size_t>& next,
              OrderedSplats& splats, const std::function<void(uint64_t)>& on_tile_done, std::function<void()> serve)
      : settings_(settings), jobs_(jobs), film_(film), next_(next), splats_(splats), on_tile_done_(on_tile_done),
        serve_(std::move(serve)) {}
  bool take(TileTask* task) override {
    const size_t i = next_.fetch_add(1);  // one tile at a time, so the workers find the rest
    if (i >= jobs_.size()) return false;
    *task = TileTask{jobs_[i], film_tile(film_, jobs_[i]), i};
    return true;
  }
  void done(const TileTask& task, uint64_t samples, std::vector<Splat>&& splats) override {
    if (settings_.path.light_traced_caustics)
      splats_.add(task.job.index, std::move(splats), job_light_paths(settings_, task.job));
    if (on_tile_done_) on_tile_done_(samples);
  }
  void between_tiles() override { serve_(); }

 private:
  const TileSettings& settings_;
  const std::vector<TileJob>& jobs_;
  Film& film_;
  std::atomic<size_t>& next_;
  OrderedSplats& splats_;
  const std::function<void(uint64_t)>& on_tile_done_;
  std::function<void()> serve_;
};

}  // namespace

void FarmMaster::render_pass(const TileSettings& settings, const std::vector<TileJob>& jobs, Film& film,
                             TileCounters* counters, const std::function<void(uint64_t)>& on_tile_done) {
  const int32_t workers = transport_.size() - 1;
  const FarmPassStart start{settings.specialisation, settings.path.guided_roulette};
  for (int32_t r = 1; r <= workers; ++r) transport_.send(r, kTagPassStart, encode(start));

  // One queue of tiles for the workers and the master's own backend. There
  // is no communication thread: between tiles, whichever rendering thread
  // gets the lock answers the workers (one thread in MPI at a time), so no
  // extra thread competes with rendering for the master's cores. Once the
  // queue is empty, this thread keeps answering until every worker is done.
  std::atomic<size_t> next{0};
  std::atomic<uint32_t> empty_replies{0};
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
      counters->add(req.counters.from_wire<TileCounters>());
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

  MasterQueue queue(settings, jobs, film, next, splats, on_tile_done, serve);
  backend_.begin_pass(settings);
  const TileCounters mine = backend_.render_tiles(queue, local_threads_);
  {
    std::lock_guard<std::mutex> lock(counters_mutex);
    counters->add(mine);
  }
  while (empty_replies < all_done) {
    serve();
    std::this_thread::sleep_for(std::chrono::microseconds(50));
  }
  if (light_paths) splats.finish();
  backend_.end_pass();
}

void FarmMaster::reduce_guide(std::vector<uint64_t>& accumulators) {
  if (!sync_guide_ || transport_.size() == 1) return;
  const auto t0 = std::chrono::steady_clock::now();
  transport_.allreduce_sum(accumulators);
  sync_seconds_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  sync_bytes_ = std::max<uint64_t>(sync_bytes_, accumulators.size() * sizeof(uint64_t));
  ++syncs_;
}

void FarmMaster::stop() {
  for (int32_t r = 1; r < transport_.size(); ++r) transport_.send(r, kTagStop, encode(FarmEmpty{}));
}

}  // namespace tessera
