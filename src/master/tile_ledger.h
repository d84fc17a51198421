// Who has which tile of a pass, as the farm master hands them out: each tile
// is waiting, held by one rank, or done. A rank that falls silent gives its
// tiles back (take_back), and they go to whoever asks next; a tile is done
// once, by the rank that held it when its result came, so a late result
// from a rank that no longer holds the tile is refused (complete() false)
// and no tile is ever counted twice. Thread-safe: the master's rendering
// threads and its message handling share it.
#pragma once

#include <cstddef>
#include <cstdint>
#include <deque>
#include <mutex>
#include <vector>

namespace tessera {

class TileLedger {
 public:
  explicit TileLedger(size_t tiles);
  // The next waiting tile for `rank`: tiles taken back first, then in
  // order. false: none waiting.
  bool issue(int32_t rank, size_t* tile);
  // `rank` returned `tile`: true (the tile is now done) when it held it.
  bool complete(int32_t rank, size_t tile);
  // Every tile `rank` holds goes back to waiting; how many.
  size_t take_back(int32_t rank);
  // The tiles `rank` finished, in tile order.
  std::vector<size_t> done_by(int32_t rank) const;
  bool all_done() const;
  bool any_waiting() const;

 private:
  static constexpr int32_t kNobody = -1;
  mutable std::mutex mutex_;
  std::vector<int32_t> holder_;  // while held: the rank; once done: the rank that did it
  std::vector<uint8_t> done_;
  std::deque<size_t> taken_back_;
  size_t next_ = 0;  // tiles below were issued at least once
  size_t done_count_ = 0;
};

}  // namespace tessera
