// The device backend's kernel body (worker/device_backend.h): one thread
// per pixel of a batch of tiles adds the pass's samples to the pixel's
// accumulators in sample order, so a pixel's sums do not depend on the
// launch's shape or timing; counters are added with integer atomics
// (order-free). Host and device code: the CUDA kernel (worker/cuda_device.cu)
// and the host emulation (worker/host_device.cpp) both call it.
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

// Everything one launch reads and writes, all in the device's memory.
struct DeviceLaunch {
  const SceneView* scene = nullptr;
  BvhView bvh;
  TileSettings settings;  // its guide view points into device memory (shared block: atomic adds)
  const DeviceTile* tiles = nullptr;
  uint32_t num_tiles = 0;
  uint32_t max_tile_pixels = 0;  // of the largest tile
  PixelAccum* pixels = nullptr;
  TileCounters* counters = nullptr;  // one, summed over the launch
};

// The integrator a specialisation is served by on the portable BVH: the
// full surface one, or the media one for scenes with media, guided or not.
// Four instantiations instead of one per effects set keep the build short.
constexpr uint32_t kServedSurface = kSpecSurfaceAll & ~kSpecGuiding;
constexpr uint32_t kServedMedia = kSpecMedia | kServedSurface;
TESSERA_HOST_DEVICE constexpr uint32_t served_specialisation(uint32_t spec) {
  return ((spec & kSpecMedia) ? kServedMedia : kServedSurface) | (spec & kSpecGuiding);
}

static_assert(sizeof(TileCounters) % sizeof(uint64_t) == 0, "TileCounters is added word by word");

template <uint32_t Spec>
TESSERA_HOST_DEVICE inline void render_device_pixel(const DeviceLaunch& launch, uint32_t tile, uint32_t pixel) {
  const DeviceTile& t = launch.tiles[tile];
  const int32_t w = t.job.x1 - t.job.x0, h = t.job.y1 - t.job.y0;
  if (pixel >= static_cast<uint32_t>(w * h)) return;
  const SceneView& s = *launch.scene;
  const BvhTracer tracer{launch.bvh, launch.scene};
  const int32_t x = t.job.x0 + static_cast<int32_t>(pixel % static_cast<uint32_t>(w));
  const int32_t y = t.job.y0 + static_cast<int32_t>(pixel / static_cast<uint32_t>(w));
  PathSettings path = launch.settings.path;
  PixelAccum& out = launch.pixels[t.first_pixel + pixel];
  PixelAccum acc = out;
  TileCounters tc;
  for (uint32_t si = t.job.sample_begin; si < t.job.sample_end; ++si)
    add_camera_sample<Spec>(s, tracer, launch.settings, path, s.camera.film_x0 + x, s.camera.film_y0 + y, si, acc, tc);
  out = acc;
  const uint64_t* mine = reinterpret_cast<const uint64_t*>(&tc);
  uint64_t* sum = reinterpret_cast<uint64_t*>(launch.counters);
  for (size_t i = 0; i < sizeof(TileCounters) / sizeof(uint64_t); ++i)
    if (mine[i] != 0) atomic_add_u64(sum + i, mine[i]);
}

}  // namespace tessera
