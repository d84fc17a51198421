// A farm worker (rank > 0): renders the tiles the master hands it with its
// own backend, pass after pass, and joins the guide's all-reduction between
// passes, until the master says stop.
#pragma once

#include "comm/transport.h"
#include "guidecache/guide.h"
#include "render/render_tile.h"
#include "render/tile_backend.h"

namespace tessera {

// settings: as make_tile_settings gives the master (the guide view is set
// here, per pass). guide: this rank's copy of the cache (nullptr: none).
void run_farm_worker(Transport& transport, TileBackend& backend, const TileSettings& settings, Guide* guide,
                     bool sync_guide, int32_t threads);

}  // namespace tessera
