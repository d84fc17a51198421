// The device backend's kernel bodies (worker/device_backend.h), host and
// device code: the CUDA kernels (worker/cuda_*.cu) and the host emulation
// (worker/host_device.cpp) both call them. A batch of tiles is two steps:
//   trace:      one thread per (pixel, sample) writes the sample's film value
//               (a pass's samples are as many threads as its pixels times
//               its spp: small images still fill a GPU);
//   accumulate: one thread per pixel adds its values in sample order, so a
//               pixel's sums do not depend on the launch's shape or timing.
// Counters and guide targets are added with integer atomics (order-free).
#pragma once

#include "kernels/bvh.h"
#include "master/film.h"
#include "worker/pixel_sample.h"
#include "worker/render_tile.h"

namespace tessera {

// A tile of a batch: its job, and where its accumulators start in the
// batch's pixel array (row-major, x1 - x0 wide).
struct DeviceTile {
  TileJob job;
  uint64_t first_pixel = 0;
};

// Samples per pixel of a tile in this pass.
TESSERA_HOST_DEVICE inline uint32_t tile_samples(const DeviceTile& t) { return t.job.sample_end - t.job.sample_begin; }

// Everything one launch reads and writes, all in the device's memory.
struct DeviceLaunch {
  const SceneView* scene = nullptr;
  BvhView bvh;
  TileSettings settings;  // its guide view points into device memory (shared block: atomic adds)
  const DeviceTile* tiles = nullptr;
  uint32_t num_tiles = 0;
  uint32_t max_tile_pixels = 0;  // of the largest tile
  uint32_t max_samples = 0;      // the most samples per pixel of any tile
  PixelAccum* pixels = nullptr;
  Rgb* values = nullptr;         // [batch pixel][sample < max_samples]: the samples' film values
  TileCounters* counters = nullptr;  // one, summed over the launch
};

// The integrator a specialisation is served by on the portable BVH: the
// full surface one, or the media one for scenes with media, guided or not.
// Four instantiations instead of one per effects set keep the build short.
constexpr uint32_t kServedSurface = kSpecSurfaceAll & ~kSpecGuiding;
constexpr uint32_t kServedMedia = kSpecMedia | kServedSurface;
// (The neural guide's bit passes through: the BVH backend serves it on the
// CPU; the device backend refuses it in begin_pass.)
TESSERA_HOST_DEVICE constexpr uint32_t served_specialisation(uint32_t spec) {
  const uint32_t guide = (spec & kSpecGuiding) ? spec & (kSpecGuiding | kSpecNeural) : 0u;
  return ((spec & kSpecMedia) ? kServedMedia : kServedSurface) | guide;
}

static_assert(sizeof(TileCounters) % sizeof(uint64_t) == 0, "TileCounters is added word by word");

// Sample `sample` (from the tile's first) of pixel `pixel` of tile `tile`.
template <uint32_t Spec>
TESSERA_HOST_DEVICE inline void trace_device_sample(const DeviceLaunch& launch, uint32_t tile, uint32_t pixel,
                                                    uint32_t sample) {
  const DeviceTile& t = launch.tiles[tile];
  const int32_t w = t.job.x1 - t.job.x0, h = t.job.y1 - t.job.y0;
  if (pixel >= static_cast<uint32_t>(w * h) || sample >= tile_samples(t)) return;
  const SceneView& s = *launch.scene;
  const BvhTracer tracer{launch.bvh, launch.scene};
  const int32_t x = t.job.x0 + static_cast<int32_t>(pixel % static_cast<uint32_t>(w));
  const int32_t y = t.job.y0 + static_cast<int32_t>(pixel / static_cast<uint32_t>(w));
  PathSettings path = launch.settings.path;
  TileCounters tc;
  launch.values[(t.first_pixel + pixel) * launch.max_samples + sample] = camera_sample_value<Spec>(
      s, tracer, launch.settings, path, s.camera.film_x0 + x, s.camera.film_y0 + y, t.job.sample_begin + sample, tc);
  const uint64_t* mine = reinterpret_cast<const uint64_t*>(&tc);
  uint64_t* sum = reinterpret_cast<uint64_t*>(launch.counters);
  for (size_t i = 0; i < sizeof(TileCounters) / sizeof(uint64_t); ++i)
    if (mine[i] != 0) atomic_add_u64(sum + i, mine[i]);
}

// Adds pixel `pixel` of tile `tile`'s sample values to its accumulators, in sample order.
TESSERA_HOST_DEVICE inline void accumulate_device_pixel(const DeviceLaunch& launch, uint32_t tile, uint32_t pixel) {
  const DeviceTile& t = launch.tiles[tile];
  const int32_t w = t.job.x1 - t.job.x0, h = t.job.y1 - t.job.y0;
  if (pixel >= static_cast<uint32_t>(w * h)) return;
  PixelAccum& out = launch.pixels[t.first_pixel + pixel];
  PixelAccum acc = out;
  const Rgb* values = launch.values + (t.first_pixel + pixel) * launch.max_samples;
  for (uint32_t i = 0; i < tile_samples(t); ++i) accumulate_sample(acc, values[i]);
  out = acc;
}

}  // namespace tessera
