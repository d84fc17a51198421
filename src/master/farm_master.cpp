#include "master/farm_master.h"

#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cstdio>
#include <cstring>
#include <stdexcept>
#include <string>
#include <thread>
#include <utility>

#include "comm/guide_wire.h"
#include "render/interrupt.h"

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

double seconds_since(std::chrono::steady_clock::time_point t) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
}

void pause_briefly() { std::this_thread::sleep_for(std::chrono::microseconds(50)); }

// A line of its own, also when a progress bar is being redrawn on the terminal.
void farm_note(const std::string& text) {
  std::fprintf(stderr, "%stessera: farm: %s\n", isatty(fileno(stderr)) ? "\r\033[K" : "", text.c_str());
  std::fflush(stderr);
}

std::string rank_error(int32_t rank, const std::string& what) { return "rank " + std::to_string(rank) + ": " + what; }

// "31 s", "2.0 s", "0.3 s".
std::string seconds_text(double s) {
  char text[32];
  std::snprintf(text, sizeof text, s < 10 ? "%.1f s" : "%.0f s", s);
  return text;
}

}  // namespace

FarmMaster::FarmMaster(Transport& transport, TileBackend& backend, const FarmMasterOptions& options)
    : transport_(transport),
      backend_(backend),
      options_(options),
      total_threads_(options.local_threads),
      workers_(static_cast<size_t>(transport.size())) {
  backends_.insert(backend.name());
  const Clock::time_point start = Clock::now();
  for (Worker& w : workers_) w.heard = start;
  auto all_joined = [&] {
    return std::all_of(workers_.begin() + 1, workers_.end(), [](const Worker& w) { return w.joined; });
  };
  while (!all_joined() && seconds_since(start) < options_.lease_s) {
    Message m;
    if (transport_.receive_within(&m, -1, std::min(0.05, options_.lease_s))) handle(m);
  }
  for (int32_t r = 1; r < transport_.size(); ++r)
    if (!workers_[r].joined)
      farm_note("rank " + std::to_string(r) + " has not said hello in " + seconds_text(options_.lease_s) +
                "; starting without it (it joins when it does)");
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

void FarmMaster::join(int32_t rank, const FarmHello& hello) {
  Worker& w = workers_[rank];
  if (w.joined) throw std::runtime_error(rank_error(rank, "said hello twice"));
  w.joined = true;
  total_threads_ += hello.threads;
  backends_.insert(hello.backend);
  if (phase_ != Phase::Idle || pass_ > 0) {
    // Its guide is the one the render started from: it may have missed folds.
    w.stale_guide = options_.guide != nullptr && options_.sync_guide;
    farm_note("rank " + std::to_string(rank) + " said hello; it joins at the next pass");
  }
}

namespace {

// The master's share of a pass: tiles from the ledger the workers also draw
// from, and the workers answered between tiles.
class MasterQueue : public TileQueue {
 public:
  MasterQueue(TileLedger& ledger, const std::vector<TileJob>& jobs, Film& film, OrderedSplats& splats,
              const TileSettings& settings, const std::function<void(uint64_t)>& on_tile_done,
              std::function<void()> serve)
      : ledger_(ledger), jobs_(jobs), film_(film), splats_(splats), settings_(settings), on_tile_done_(on_tile_done),
        serve_(std::move(serve)) {}
  bool take(TileTask* task) override {
    size_t i = 0;
    if (!ledger_.issue(0, &i)) return false;  // one tile at a time, so the workers find the rest
    *task = TileTask{jobs_[i], film_tile(film_, jobs_[i]), i};
    return true;
  }
  void done(const TileTask& task, uint64_t samples, std::vector<Splat>&& splats) override {
    ledger_.complete(0, task.slot);  // the master never leaves itself out: always its own
    if (settings_.path.light_traced_caustics)
      splats_.add(task.job.index, std::move(splats), job_light_paths(settings_, task.job));
    if (on_tile_done_) on_tile_done_(samples);
  }
  void between_tiles() override { serve_(); }

 private:
  TileLedger& ledger_;
  const std::vector<TileJob>& jobs_;
  Film& film_;
  OrderedSplats& splats_;
  const TileSettings& settings_;
  const std::function<void(uint64_t)>& on_tile_done_;
  std::function<void()> serve_;
};

}  // namespace

void FarmMaster::render_pass(const TileSettings& settings, const std::vector<TileJob>& jobs, Film& film,
                             TileCounters* counters, const std::function<void(uint64_t)>& on_tile_done) {
  ++pass_;
  if (options_.pause) options_.pause("pass");
  pass_settings_ = settings;
  pass_jobs_ = jobs;
  pass_learns_ = options_.guide != nullptr && options_.sync_guide && (settings.specialisation & kSpecGuiding) != 0;
  round_ = 0;
  rounds_in_.clear();
  stand_ins_due_.clear();
  stand_ins_.clear();
  round_sums_.clear();
  pass_start_guide_.clear();
  relearn_.clear();
  ledger_ = std::make_unique<TileLedger>(jobs.size());
  PassTiles pass{settings, jobs, film, counters, on_tile_done, OrderedSplats(film, jobs.size())};
  // Messages about the pass's tiles find them here until the pass is over,
  // however it ends.
  struct TilesOut {
    FarmMaster& m;
    ~TilesOut() {
      std::lock_guard<std::mutex> lock(m.comm_mutex_);
      m.tiles_ = nullptr;
      m.phase_ = Phase::Idle;
    }
  } tiles_out{*this};
  {
    std::lock_guard<std::mutex> lock(comm_mutex_);
    tiles_ = &pass;
    phase_ = Phase::Tiles;
    admit_workers(settings);
  }
  backend_.begin_pass(settings);
  render_own_share(pass);
  // The learning of finished tiles whose rank was left out (stand_in.h).
  std::vector<TileJob> relearn;
  {
    std::lock_guard<std::mutex> lock(comm_mutex_);
    relearn.swap(relearn_);
  }
  render_for_learning(backend_, relearn, options_.local_threads, [this] { serve(); });
  if (settings.path.light_traced_caustics) pass.splats.finish();
  backend_.end_pass();
}

// Every joined worker that has been heard from since it was left out (if
// it was) takes part; one that missed a fold gets the guide as it stands.
void FarmMaster::admit_workers(const TileSettings& settings) {
  FarmPassStart start{pass_, settings.specialisation, settings.path.guided_roulette, {}};
  for (int32_t r = 1; r < transport_.size(); ++r) {
    Worker& w = workers_[r];
    if (!w.joined || w.out) continue;
    FarmPassStart mine = start;
    if (w.stale_guide) mine.guide = pass_start_guide();
    if (!w.active && pass_ > 1)
      farm_note("rank " + std::to_string(r) + (w.took_part ? " takes part again" : " takes part") + " from pass " +
                std::to_string(pass_) + (mine.guide.empty() ? "" : ", with the master's guide"));
    transport_.send(r, kTagPassStart, encode(mine));
    w.active = true;
    w.took_part = true;
    w.stale_guide = false;
    w.empty_replies = 0;
    w.heard = Clock::now();
  }
}

// The master renders until no tile waits, then answers the workers until
// every tile is done (rendering again any tile a silent worker gave back).
void FarmMaster::render_own_share(PassTiles& pass) {
  MasterQueue queue(*ledger_, pass.jobs, pass.film, pass.splats, pass.settings, pass.on_tile_done, [this] { serve(); });
  for (;;) {
    if (ledger_->any_waiting()) {
      const TileCounters mine = backend_.render_tiles(queue, options_.local_threads);
      std::lock_guard<std::mutex> lock(counters_mutex_);
      pass.counters->add(mine);
    }
    serve();
    {
      std::lock_guard<std::mutex> lock(comm_mutex_);
      if (tiles_finished()) return;
    }
    pause_briefly();
  }
}

bool FarmMaster::tiles_finished() const {
  if (!ledger_->all_done()) return false;
  for (int32_t r = 1; r < transport_.size(); ++r)
    if (owes(r)) return false;
  return true;
}

// Answers whatever has arrived and leaves out workers silent past the
// lease. Any thread; one at a time (the others go back to rendering).
void FarmMaster::serve() {
  std::unique_lock<std::mutex> lock(comm_mutex_, std::try_to_lock);
  if (!lock) return;
  Message m;
  while (transport_.try_receive(&m, -1)) handle(m);
  check_leases();
}

void FarmMaster::handle(Message& m) {
  const int32_t r = m.source;
  if (r <= 0 || r >= transport_.size()) throw std::runtime_error("a message from rank " + std::to_string(r));
  Worker& w = workers_[r];
  w.heard = Clock::now();
  if (w.out) {
    w.out = false;
    farm_note("rank " + std::to_string(r) + " is heard from again; it takes part from the next pass");
  }
  switch (m.tag) {
    case kTagHello: join(r, decode<FarmHello>(m.bytes)); break;
    case kTagRequest: {
      TileRequest req = decode<TileRequest>(m.bytes);
      on_request(r, req);
      break;
    }
    case kTagRound: {
      GuideRound round = decode<GuideRound>(m.bytes);
      on_round(r, round);
      break;
    }
    case kTagPing: transport_.send(r, kTagPong, {}); break;
    case kTagBye: w.stopped = true; break;
    case kTagError: throw std::runtime_error(rank_error(r, decode<FarmError>(m.bytes).message));
    default: throw std::runtime_error(rank_error(r, "unexpected message"));
  }
}

// A worker's finished tiles and its request for more. A request from a pass
// it no longer takes part in gets "none left": its results are another
// rank's to give (the tiles went back to the ledger when it was left out).
void FarmMaster::on_request(int32_t r, TileRequest& req) {
  if (req.interrupted) note_worker_interrupt();
  Worker& w = workers_[r];
  TileJobs reply{req.pass, {}};
  if (tiles_ != nullptr && req.pass == pass_ && w.active) {
    accept_results(r, req);
    for (uint32_t k = 0; k < req.capacity; ++k) {
      size_t i = 0;
      if (!ledger_->issue(r, &i)) break;
      reply.jobs.push_back(tile_work(pass_jobs_[i], tiles_->film));
    }
    if (reply.jobs.empty()) ++w.empty_replies;
  }
  transport_.send(r, kTagJobs, encode(reply));
}

void FarmMaster::accept_results(int32_t r, TileRequest& req) {
  PassTiles& pass = *tiles_;
  const bool light_paths = pass.settings.path.light_traced_caustics;
  for (TileWork& tw : req.results) {
    // Only a tile this rank holds, as it was handed out.
    const size_t i = tw.job.index;
    if (i >= pass.jobs.size() || std::memcmp(&tw.job, &pass.jobs[i], sizeof(TileJob)) != 0 ||
        tw.pixels.size() != static_cast<size_t>(tw.job.x1 - tw.job.x0) * (tw.job.y1 - tw.job.y0) ||
        (!light_paths && !tw.splats.empty()) || !ledger_->complete(r, i))
      throw std::runtime_error(rank_error(r, "malformed tile result"));
    const TileJob& j = pass.jobs[i];
    size_t k = 0;
    for (int32_t y = j.y0; y < j.y1; ++y)
      for (int32_t x = j.x0; x < j.x1; ++x) pass.film.at(x, y) = tw.pixels[k++];
    if (light_paths) pass.splats.add(j.index, std::move(tw.splats), job_light_paths(pass.settings, j));
    if (pass.on_tile_done) pass.on_tile_done(job_samples(j));
  }
  std::lock_guard<std::mutex> lock(counters_mutex_);
  pass.counters->add(req.counters.from_wire<TileCounters>());
}

void FarmMaster::on_round(int32_t r, GuideRound& round) {
  if (round.pass != pass_ || !workers_[r].active) return;  // from a pass it was left out of
  rounds_in_[r] = std::move(round);
}

// What the pass waits for from a worker: "none left" answers to its open
// requests while tiles render, its accumulators while a round is combined.
bool FarmMaster::owes(int32_t r) const {
  const Worker& w = workers_[r];
  if (!w.active) return false;
  if (phase_ == Phase::Tiles) return w.empty_replies < kRequestsInFlight;
  if (phase_ == Phase::Rounds) {
    auto it = rounds_in_.find(r);
    return it == rounds_in_.end() || it->second.round != round_;
  }
  return false;
}

void FarmMaster::check_leases() {
  for (int32_t r = 1; r < transport_.size(); ++r) {
    if (!owes(r)) continue;
    const double silent = seconds_since(workers_[r].heard);
    if (silent > options_.lease_s) leave_out(r, silent);
  }
}

// The worker's tiles go back to the ledger and its learning from the tiles
// it finished is redone by the master: now (while tiles render) or by a
// stand-in (in the rounds, after it had sent some).
void FarmMaster::leave_out(int32_t r, double silent_s) {
  Worker& w = workers_[r];
  w.active = false;
  w.out = true;
  w.stale_guide = options_.guide != nullptr && options_.sync_guide;
  rounds_in_.erase(r);
  const size_t given_back = phase_ == Phase::Tiles ? ledger_->take_back(r) : 0;
  std::vector<TileJob> finished;
  if (pass_learns_)
    for (size_t i : ledger_->done_by(r)) finished.push_back(pass_jobs_[i]);
  std::string note = "rank " + std::to_string(r) + " silent for " + seconds_text(silent_s);
  if (phase_ == Phase::Rounds) note += " during the guide's learning";
  else if (given_back == 0) note += "; it held no tiles";
  else note += "; its " + std::to_string(given_back) + " tiles re-issued";
  if (!finished.empty()) {
    note += "; rank 0 relearns its " + std::to_string(finished.size()) + " finished tiles";
    if (phase_ == Phase::Tiles) relearn_.insert(relearn_.end(), finished.begin(), finished.end());
    else stand_ins_due_.emplace_back(r, std::move(finished));
  }
  farm_note(note);
}

// The guide as this pass began: the fields only change when a round is
// folded, so until the first fold the master's own guide is that guide.
const Bytes& FarmMaster::pass_start_guide() {
  if (pass_start_guide_.empty()) {
    if (round_ > 0) throw std::logic_error("FarmMaster: the pass's guide was not kept before its first fold");
    pass_start_guide_ = guide_to_bytes(*options_.guide, options_.scene_fingerprint);
  }
  return pass_start_guide_;
}

// One round of the pass's learning: every active worker's accumulators, the
// master's own and its stand-ins', summed; the sum goes back to the workers
// and each rank folds it (the renderer folds the master's).
void FarmMaster::reduce_guide(std::vector<uint64_t>& acc) {
  if (!options_.sync_guide || transport_.size() == 1) return;
  if (options_.guide == nullptr) throw std::logic_error("FarmMaster: a guided pass without FarmMasterOptions::guide");
  const auto t0 = Clock::now();
  const uint32_t round = round_;
  await_round();
  std::vector<uint64_t> sum = acc;
  add_stand_ins(round, &sum);
  for (auto& [r, in] : rounds_in_) {
    if (in.words.size() != sum.size()) throw std::runtime_error(rank_error(r, "its learning has another size"));
    for (size_t i = 0; i < sum.size(); ++i) sum[i] += in.words[i];  // integers: order-free
  }
  rounds_in_.clear();
  const Bytes out = encode(GuideRound{pass_, round, sum});
  for (int32_t r = 1; r < transport_.size(); ++r)
    if (workers_[r].active) transport_.send(r, kTagRound, out);
  // Later rounds may still need the pass's starting guide, this sum, and
  // the stand-ins folded to where every rank is.
  if (options_.guide->max_rounds() > 1) {
    if (round == 0) pass_start_guide();
    round_sums_.push_back(sum);
    for (StandIn& s : stand_ins_) s.fold_round(round, sum);
  }
  acc = std::move(sum);
  {
    std::lock_guard<std::mutex> lock(comm_mutex_);
    phase_ = Phase::Idle;
    ++round_;
  }
  sync_seconds_ += std::chrono::duration<double>(Clock::now() - t0).count();
  sync_bytes_ = std::max<uint64_t>(sync_bytes_, acc.size() * sizeof(uint64_t));
  ++syncs_;
}

// Until every worker that takes part has sent this round (or was left out).
void FarmMaster::await_round() {
  {
    std::lock_guard<std::mutex> lock(comm_mutex_);
    phase_ = Phase::Rounds;
    // They owe it from now: the master may have been busy since they last spoke.
    for (Worker& w : workers_)
      if (w.active) w.heard = std::max(w.heard, Clock::now());
  }
  for (;;) {
    serve();
    {
      std::lock_guard<std::mutex> lock(comm_mutex_);
      bool all_in = true;
      for (int32_t r = 1; r < transport_.size(); ++r) all_in = all_in && !owes(r);
      if (all_in) return;
    }
    pause_briefly();
  }
}

// Stand-ins for workers left out during the rounds: made when due (they
// catch up with the rounds already folded), then they add theirs each round.
void FarmMaster::add_stand_ins(uint32_t round, std::vector<uint64_t>* sum) {
  for (auto& [r, tiles] : stand_ins_due_) {
    (void)r;
    StandIn s(guide_from_bytes(pass_start_guide(), options_.scene_fingerprint), std::move(tiles));
    s.render(backend_, pass_settings_, options_.local_threads, [this] { serve(); });
    s.catch_up(round_sums_);
    stand_ins_.push_back(std::move(s));
  }
  stand_ins_due_.clear();
  for (StandIn& s : stand_ins_) s.add_round(round, sum);
}

std::vector<SilentRank> FarmMaster::finish() {
  std::lock_guard<std::mutex> lock(comm_mutex_);
  for (int32_t r = 1; r < transport_.size(); ++r) transport_.send(r, kTagStop, encode(FarmEmpty{}));
  // Workers that were taking part answer at once; the silent ones are not waited for.
  const Clock::time_point start = Clock::now();
  auto answered = [&](const Worker& w) { return w.stopped || !w.joined || w.out; };
  while (!std::all_of(workers_.begin() + 1, workers_.end(), answered) && seconds_since(start) < options_.lease_s) {
    Message m;
    if (!transport_.receive_within(&m, -1, 0.05)) continue;
    if (m.tag == kTagBye && m.source > 0 && m.source < transport_.size()) workers_[m.source].stopped = true;
    if (m.source > 0 && m.source < transport_.size()) workers_[m.source].heard = Clock::now();
  }
  std::vector<SilentRank> silent;
  for (int32_t r = 1; r < transport_.size(); ++r)
    if (!workers_[r].stopped) silent.push_back(SilentRank{r, seconds_since(workers_[r].heard)});
  return silent;
}

}  // namespace tessera
