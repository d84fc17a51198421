// Light-path splats land anywhere in the image, so tiles rendered in
// parallel cannot add them to the film directly without making the sums
// depend on thread timing. Each tile's list is handed in when the tile is
// done and added in tile order (its TileJob::index): the film is the same
// for any thread or rank count. Lists wait only until the tiles before them
// are in: with tiles taken in order (as the executors do), few wait.
#pragma once

#include <cstdint>
#include <mutex>
#include <vector>

#include "render/film.h"

namespace tessera {

class OrderedSplats {
 public:
  OrderedSplats(Film& film, size_t jobs);
  // Thread-safe. index < jobs, each once.
  void add(size_t index, std::vector<Splat>&& splats, uint64_t light_paths);
  // Throws unless every job's list was added.
  void finish() const;

 private:
  Film& film_;
  std::mutex mutex_;
  std::vector<std::vector<Splat>> waiting_;
  std::vector<uint64_t> light_paths_;
  std::vector<char> ready_;
  size_t next_ = 0;
};

}  // namespace tessera
