#include "master/stand_in.h"

#include <atomic>
#include <stdexcept>
#include <string>

#include "render/guide_binding.h"

namespace tessera {
namespace {

// The tiles, each into a scratch pixel buffer of its own.
class LearningQueue : public TileQueue {
 public:
  LearningQueue(const std::vector<TileJob>& tiles, const std::function<void()>& between_tiles)
      : tiles_(tiles), pixels_(tiles.size()), between_tiles_(between_tiles) {}
  bool take(TileTask* task) override {
    const size_t i = next_.fetch_add(1);
    if (i >= tiles_.size()) return false;
    const TileJob& j = tiles_[i];
    pixels_[i].assign(static_cast<size_t>(j.x1 - j.x0) * (j.y1 - j.y0), PixelAccum{});
    *task = TileTask{j, TilePixels{pixels_[i].data(), j.x1 - j.x0}, i};
    return true;
  }
  void done(const TileTask& task, uint64_t, std::vector<Splat>&&) override { pixels_[task.slot] = {}; }
  void between_tiles() override {
    if (between_tiles_) between_tiles_();
  }

 private:
  const std::vector<TileJob>& tiles_;
  std::vector<std::vector<PixelAccum>> pixels_;
  std::atomic<size_t> next_{0};
  const std::function<void()>& between_tiles_;
};

}  // namespace

void render_for_learning(TileBackend& backend, const std::vector<TileJob>& tiles, int32_t threads,
                         const std::function<void()>& between_tiles) {
  if (tiles.empty()) return;
  LearningQueue queue(tiles, between_tiles);
  backend.render_tiles(queue, threads);  // its counters were counted when the tiles' results came
}

StandIn::StandIn(std::unique_ptr<Guide> pass_start, std::vector<TileJob> tiles)
    : guide_(std::move(pass_start)), tiles_(std::move(tiles)) {}

void StandIn::render(TileBackend& backend, const TileSettings& pass_settings, int32_t threads,
                     const std::function<void()>& between_tiles) {
  TileSettings settings = pass_settings;
  bind_guide(*guide_, &settings);
  backend.begin_pass(settings);
  render_for_learning(backend, tiles_, threads, between_tiles);
  backend.end_pass();
}

void StandIn::catch_up(const std::vector<std::vector<uint64_t>>& history) {
  for (uint32_t r = next_round_; r < history.size(); ++r) {
    begin_round(r);  // its own accumulators are in history[r] already
    fold_round(r, history[r]);
  }
}

void StandIn::begin_round(uint32_t round) {
  if (round != next_round_ || round >= guide_->rounds()) throw std::logic_error("StandIn: rounds out of step");
  pending_ = &guide_->round_accumulators(round);
}

void StandIn::add_round(uint32_t round, std::vector<uint64_t>* sum) {
  begin_round(round);
  if (sum->size() != pending_->size())
    throw std::logic_error("StandIn: round " + std::to_string(round) + " has another size than the master's");
  for (size_t i = 0; i < sum->size(); ++i) (*sum)[i] += (*pending_)[i];  // integers: wrap-around sums, order-free
}

void StandIn::fold_round(uint32_t round, const std::vector<uint64_t>& sum) {
  if (round != next_round_ || pending_ == nullptr) throw std::logic_error("StandIn: fold out of step");
  *pending_ = sum;
  guide_->fold_round(round);
  pending_ = nullptr;
  ++next_round_;
}

}  // namespace tessera
