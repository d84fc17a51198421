// The backend seam: what renders a pass's tiles on this process. The pass
// loop (render/renderer.cpp), the farm master and the farm worker hand tiles
// to a TileBackend through a TileQueue and never see how they are traced:
// Embree on this process's threads (render/embree_backend.h), the portable
// BVH on them (render/bvh_backend.h), or a device (render/device_backend.h:
// CUDA, or the GPU's kernel emulated on the host).
// make_tile_backend (render/backends.h) picks one.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "render/film.h"
#include "render/render_tile.h"

namespace tessera {

// A tile to render: the job (pixels and sample range), where its pixel
// accumulators are, and the queue's own handle on it.
struct TileTask {
  TileJob job;
  TilePixels pixels;
  size_t slot = 0;
};

// A pass's tiles, as the pass loop hands them to a backend. take() and
// done() may be called from any thread; an implementation synchronises.
class TileQueue {
 public:
  virtual ~TileQueue() = default;
  // The next tile; false: none left in this pass.
  virtual bool take(TileTask* task) = 0;
  // A tile is rendered: its sample count (progress) and, with light-traced
  // caustics, its light-path splats in order.
  virtual void done(const TileTask& task, uint64_t samples, std::vector<Splat>&& splats) = 0;
  // Called between tiles by whichever thread is free: the farm master
  // answers its workers here.
  virtual void between_tiles() {}
};

class TileBackend {
 public:
  virtual ~TileBackend() = default;
  // What the log and stats call it: embree, bvh, cuda.
  virtual std::string name() const = 0;
  // Whether it runs the full integrator whatever a pass's specialisation
  // narrows (the portable BVH and the device do): a local render's stats
  // then name the full one.
  virtual bool serves_full_integrator() const { return false; }
  // How many tiles a farm worker asks for at a time: a few per host thread,
  // or a device's batch.
  virtual uint32_t tiles_per_request(int32_t threads) const { return static_cast<uint32_t>(threads); }
  // A pass begins. Its tiles render with `settings`; what they learn is
  // added into the accumulator block of settings.path.guide (when it has one)
  // by end_pass().
  virtual void begin_pass(const TileSettings& settings) = 0;
  // Renders tiles from `queue` until it has none, on `threads` host threads
  // (a GPU backend drives its device from one), and returns their counters
  // summed. May be called more than once per pass (a farm worker calls it
  // per batch of tiles).
  virtual TileCounters render_tiles(TileQueue& queue, int32_t threads) = 0;
  // The pass is over: the guide learning of every tile is in the block.
  virtual void end_pass() = 0;
};

}  // namespace tessera
