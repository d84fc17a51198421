#include "master/tile_ledger.h"

namespace tessera {

TileLedger::TileLedger(size_t tiles) : holder_(tiles, kNobody), done_(tiles, 0) {}

bool TileLedger::issue(int32_t rank, size_t* tile) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (!taken_back_.empty()) {
    *tile = taken_back_.front();
    taken_back_.pop_front();
  } else if (next_ < holder_.size()) {
    *tile = next_++;
  } else {
    return false;
  }
  holder_[*tile] = rank;
  return true;
}

bool TileLedger::complete(int32_t rank, size_t tile) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (tile >= holder_.size() || done_[tile] || holder_[tile] != rank) return false;
  done_[tile] = 1;
  ++done_count_;
  return true;
}

size_t TileLedger::take_back(int32_t rank) {
  std::lock_guard<std::mutex> lock(mutex_);
  size_t n = 0;
  for (size_t t = 0; t < next_; ++t) {
    if (done_[t] || holder_[t] != rank) continue;
    holder_[t] = kNobody;
    taken_back_.push_back(t);
    ++n;
  }
  return n;
}

std::vector<size_t> TileLedger::done_by(int32_t rank) const {
  std::lock_guard<std::mutex> lock(mutex_);
  std::vector<size_t> tiles;
  for (size_t t = 0; t < next_; ++t)
    if (done_[t] && holder_[t] == rank) tiles.push_back(t);
  return tiles;
}

bool TileLedger::all_done() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return done_count_ == holder_.size();
}

bool TileLedger::any_waiting() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return !taken_back_.empty() || next_ < holder_.size();
}

}  // namespace tessera
