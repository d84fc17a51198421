// The master standing in for a worker left out of a guided pass (silent past
// the lease, master/farm_master.h) after it had finished some of the pass's
// tiles: their pixels are in the image, but what the guide learned from them
// is on the silent rank. What a tile teaches depends only on the guide the
// pass started from and on the tile (random numbers come from seed, pixel and
// sample index, never from who renders), so the master renders those tiles
// again for their learning alone and adds it in place of the silent rank's:
// the sums, and so every rank's field and the image, are what they would
// have been.
//
// Left out while the pass's tiles render: the master renders the tiles into
// its own guide before the first round (render_for_learning). Left out at
// round r of the learning (the rank had sent rounds 0..r-1): a StandIn, a
// copy of the guide as the pass started, renders them and folds the sums of
// rounds 0..r-1 as the silent rank did, then adds its learning from round r on.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <vector>

#include "guidecache/guide.h"
#include "render/render_tile.h"
#include "render/tile_backend.h"

namespace tessera {

// Renders `tiles` on `backend` (already in a pass) for what the pass's guide
// learns from them: their pixels, splats and counters are dropped.
// between_tiles: called between tiles (the master answers its workers).
void render_for_learning(TileBackend& backend, const std::vector<TileJob>& tiles, int32_t threads,
                         const std::function<void()>& between_tiles);

class StandIn {
 public:
  // pass_start: a copy of the guide as the pass began (its learning empty).
  StandIn(std::unique_ptr<Guide> pass_start, std::vector<TileJob> tiles);
  // Renders the tiles with the pass's settings bound to this copy of the guide.
  void render(TileBackend& backend, const TileSettings& pass_settings, int32_t threads,
              const std::function<void()>& between_tiles);
  // Folds the sums of the rounds already combined (history[r]: round r's).
  void catch_up(const std::vector<std::vector<uint64_t>>& history);
  // Round `round`: adds this copy's accumulators into *sum (same size).
  void add_round(uint32_t round, std::vector<uint64_t>* sum);
  // Folds round `round`'s sum, as every rank does.
  void fold_round(uint32_t round, const std::vector<uint64_t>& sum);
  uint32_t next_round() const { return next_round_; }

 private:
  void begin_round(uint32_t round);

  std::unique_ptr<Guide> guide_;
  std::vector<TileJob> tiles_;
  uint32_t next_round_ = 0;
  std::vector<uint64_t>* pending_ = nullptr;  // the round under way's accumulators
};

}  // namespace tessera
