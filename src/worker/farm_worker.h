// A farm worker (rank > 0): renders the tiles the master hands it with its
// own backend, pass after pass, and sends the master each round of its guide
// learning between passes, until the master says stop.
//
// It waits only on the master. A worker the master left out of a pass (it
// was silent past the lease: docs/farm.md, "A silent rank") finds out when a
// later pass begins or the render ends while it is still in the old one: it
// drops that pass and, if it missed a fold, takes the guide the master sends
// with the next pass. A master silent past `timeout_s` ends the job.
#pragma once

#include <functional>
#include <memory>
#include <stdexcept>

#include "comm/transport.h"
#include "guidecache/guide.h"
#include "render/render_tile.h"
#include "render/tile_backend.h"

namespace tessera {

struct FarmWorkerOptions {
  bool sync_guide = true;  // --guide-sync pass
  int32_t threads = 1;     // host threads it renders with
  // --farm-timeout: how long it waits for the master, asking after it
  // (Ping) every quarter of that, before it gives up.
  double timeout_s = 600.0;
  uint64_t scene_fingerprint = 0;  // to read the guide the master sends
  // Test hook: called with "tiles" before it renders a batch, "result"
  // after it returned one, "round" before it sends a round of learning, and
  // "bye" after it answered Stop.
  std::function<void(const char*)> pause;
};

// The master sent nothing for timeout_s while this worker waited for it:
// the job cannot go on (only the master has the image).
class MasterSilent : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// settings: as make_tile_settings gives the master (the guide view is set
// here, per pass). guide: this rank's copy of the cache (null: none); the
// worker replaces it when the master sends its own. Throws MasterSilent.
void run_farm_worker(Transport& transport, TileBackend& backend, const TileSettings& settings,
                     std::unique_ptr<Guide>& guide, const FarmWorkerOptions& options);

}  // namespace tessera
