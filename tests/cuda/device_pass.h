// A pass over a whole film with any TileBackend, with no renderer around
// it: what the GPU check (device_backend_on_device.cpp) and the fixtures it
// compares with (make_gpu_fixtures.cpp) both run, so their tiles and
// sample ranges are the same.
#pragma once

#include <algorithm>
#include <atomic>
#include <vector>

#include "../film_stats.h"
#include "render/film.h"
#include "render/tile_backend.h"

namespace tessera::cuda_check {

class FilmTiles : public TileQueue {
 public:
  FilmTiles(Film& film, uint32_t sample_begin, uint32_t sample_end) : film_(film) {
    for (int32_t y = 0; y < film.height; y += 16)
      for (int32_t x = 0; x < film.width; x += 16)
        jobs_.push_back(TileJob{x, y, std::min(x + 16, film.width), std::min(y + 16, film.height), sample_begin,
                                sample_end, static_cast<uint32_t>(jobs_.size())});
  }
  bool take(TileTask* task) override {
    const size_t i = next_++;
    if (i >= jobs_.size()) return false;
    *task = TileTask{jobs_[i], film_tile(film_, jobs_[i]), i};
    return true;
  }
  void done(const TileTask&, uint64_t, std::vector<Splat>&&) override {}

 private:
  Film& film_;
  std::vector<TileJob> jobs_;
  std::atomic<size_t> next_{0};
};

// Samples [sample_begin, sample_end) of every pixel, added to the film.
inline TileCounters render_film_pass(TileBackend& backend, const TileSettings& settings, Film& film,
                                     uint32_t sample_begin, uint32_t sample_end, int32_t threads = 1) {
  FilmTiles tiles(film, sample_begin, sample_end);
  backend.begin_pass(settings);
  const TileCounters c = backend.render_tiles(tiles, threads);
  backend.end_pass();
  return c;
}

}  // namespace tessera::cuda_check
