// The device backend's kernel bodies (render/device_backend.h), host and
// device code: the CUDA kernels (render/cuda_*.cu) and the host emulation
// (render/host_device.cpp) both call them. A batch of tiles is two steps:
//   trace:      one thread per (pixel, sample) writes the sample's film value
//               (a pass's samples are as many threads as its pixels times
//               its spp: small images still fill a GPU);
//   accumulate: one thread per pixel adds its values in sample order, so a
//               pixel's sums do not depend on the launch's shape or timing.
// Counters and guide targets are added with integer atomics (order-free);
// the neural guide's targets are gathered per tile after the trace.
#pragma once

#include <stdexcept>
#include <type_traits>

#include "kernels/bvh.h"
#include "render/film.h"
#include "render/pixel_sample.h"
#include "render/render_tile.h"

namespace tessera {

// A tile of a batch: its job, and where its accumulators start in the
// batch's pixel array (row-major, x1 - x0 wide). With the neural guide
// learning: each learning path (pixel, learning sample) has
// kNeuralPathTargets target slots, the tile's from path first_target_path
// on, pixel-major (the order a CPU thread traces them in), and room for
// what the tile can keep (its capacity, or 8 per learning path if fewer)
// from first_room on.
struct DeviceTile {
  TileJob job;
  uint64_t first_pixel = 0;
  uint64_t first_target_path = 0;
  uint64_t first_room = 0;
  uint32_t room = 0;
  uint32_t learning_samples = 0;  // of the job's samples (0: the tile records no targets)
  Float keep_prob = 1.f;          // NeuralSampleSink::keep_prob for the tile
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
  // The neural guide's learning targets (null: not recorded): slots per
  // learning path (DeviceTile), how many each path kept, and the launch's
  // rejected (non-finite, too large) and dropped targets; then each tile's
  // gathered (gather_device_targets) into its room (DeviceTile), how many
  // ([tile]) and how many were dropped beyond it ([num_tiles + tile]).
  NeuralTrainingSample* targets = nullptr;
  uint32_t* target_counts = nullptr;
  uint64_t* sink_words = nullptr;  // [kDeviceSinkWords]: rejected, too large, dropped, then the mixture statistics
  NeuralTrainingSample* tile_targets = nullptr;
  uint32_t* tile_target_counts = nullptr;
};
// Words of DeviceLaunch::sink_words: a launch's sink counters, summed.
constexpr uint32_t kDeviceSinkWords = 3 + kNeuralMixCandidates + 2;

// The integrator a specialisation is served by on the portable BVH: the
// full surface one, or the media one for scenes with media, guided or not.
// Four instantiations (six with the neural guide's, whose bit passes
// through) instead of one per effects set keep the build short.
constexpr uint32_t kServedSurface = kSpecSurfaceAll & ~kSpecGuiding;
constexpr uint32_t kServedMedia = kSpecMedia | kServedSurface;
TESSERA_HOST_DEVICE constexpr uint32_t served_specialisation(uint32_t spec) {
  const uint32_t guide = (spec & kSpecGuiding) ? spec & (kSpecGuiding | kSpecNeural) : 0u;
  return ((spec & kSpecMedia) ? kServedMedia : kServedSurface) | guide;
}

// The one switch from a specialisation to its served instantiation:
// fn(std::integral_constant<uint32_t, Served>{}) for the portable BVH's
// backends (render/bvh_backend.cpp, render/host_device.cpp,
// render/cuda_device.cu). WithMedia false: a backend without media
// kernels (the CUDA device), for which a media specialisation is a logic error.
template <bool WithMedia = true, class Fn>
decltype(auto) dispatch_served(uint32_t spec, Fn&& fn) {
  using std::integral_constant;
  switch (served_specialisation(spec)) {
    case kServedSurface: return fn(integral_constant<uint32_t, kServedSurface>{});
    case kServedSurface | kSpecGuiding: return fn(integral_constant<uint32_t, kServedSurface | kSpecGuiding>{});
    case kServedSurface | kSpecGuiding | kSpecNeural:
      return fn(integral_constant<uint32_t, kServedSurface | kSpecGuiding | kSpecNeural>{});
    default: break;
  }
  if constexpr (WithMedia) {
    switch (served_specialisation(spec)) {
      case kServedMedia | kSpecGuiding: return fn(integral_constant<uint32_t, kServedMedia | kSpecGuiding>{});
      case kServedMedia | kSpecGuiding | kSpecNeural:
        return fn(integral_constant<uint32_t, kServedMedia | kSpecGuiding | kSpecNeural>{});
      default: return fn(integral_constant<uint32_t, kServedMedia>{});
    }
  } else {
    throw std::logic_error("a media specialisation on a backend without media kernels");
  }
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
  const int32_t x = t.job.x0 + static_cast<int32_t>(pixel % static_cast<uint32_t>(w));
  const int32_t y = t.job.y0 + static_cast<int32_t>(pixel / static_cast<uint32_t>(w));
  PathSettings path = launch.settings.path;
  TileCounters tc;
  const BvhTracer tracer{launch.bvh, launch.scene, &tc.path.untraceable_rays};
  const uint32_t si = t.job.sample_begin + sample;
  // The neural guide's learning targets: a sink of the path's own.
  NeuralSampleSink sink;
  uint64_t path_slot = 0;
  if constexpr ((Spec & kSpecNeural) != 0) {
    path.neural.sink = nullptr;
    path.neural_first = nullptr;  // each sample alone (the CPU tile loop's first sites are host memory)
    const GuideLearnSchedule& learn = launch.settings.learn;
    if (launch.targets != nullptr && t.learning_samples > 0 && learn.learns(si)) {
      uint32_t ordinal = 0;  // among the tile's learning samples
      for (uint32_t k = t.job.sample_begin; k < si; ++k) ordinal += learn.learns(k) ? 1u : 0u;
      path_slot = t.first_target_path + uint64_t{pixel} * t.learning_samples + ordinal;
      sink.data = launch.targets + path_slot * kNeuralPathTargets;
      sink.capacity = kNeuralPathTargets;
      sink.tile = t.job.index;
      sink.keep_prob = t.keep_prob;
      path.neural.sink = &sink;
    }
  }
  launch.values[(t.first_pixel + pixel) * launch.max_samples + sample] =
      camera_sample_value<Spec>(s, tracer, launch.settings, path, s.camera.film_x0 + x, s.camera.film_y0 + y, si, tc);
  if constexpr ((Spec & kSpecNeural) != 0) {
    if (path.neural.sink != nullptr) {
      launch.target_counts[path_slot] = sink.count;
      if (sink.rejected_nonfinite) atomic_add_u64(launch.sink_words + 0, sink.rejected_nonfinite);
      if (sink.rejected_large) atomic_add_u64(launch.sink_words + 1, sink.rejected_large);
      if (sink.dropped) atomic_add_u64(launch.sink_words + 2, sink.dropped);
      for (uint32_t k = 0; k < kNeuralMixCandidates; ++k)
        if (sink.mix_moments[k]) atomic_add_u64(launch.sink_words + 3 + k, sink.mix_moments[k]);
      if (sink.mix_vertices) atomic_add_u64(launch.sink_words + 3 + kNeuralMixCandidates, sink.mix_vertices);
      if (sink.mix_rejected) atomic_add_u64(launch.sink_words + 4 + kNeuralMixCandidates, sink.mix_rejected);
    }
  }
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

// After the trace: tile `tile`'s learning targets in the order a CPU thread
// records them (pixels row-major, then samples, then along the path),
// within the tile's capacity as a CPU sink's (the rest counted as
// dropped), packed at the tile's place in tile_targets: what comes back to
// the host is a tile's kept targets, not every path's slots.
TESSERA_HOST_DEVICE inline void gather_device_targets(const DeviceLaunch& launch, uint32_t tile) {
  if (launch.targets == nullptr) return;
  const DeviceTile& t = launch.tiles[tile];
  const uint64_t paths = uint64_t(t.job.x1 - t.job.x0) * uint64_t(t.job.y1 - t.job.y0) * t.learning_samples;
  NeuralTrainingSample* out = launch.tile_targets + t.first_room;
  uint32_t kept = 0, dropped = 0;
  for (uint64_t p = t.first_target_path; p < t.first_target_path + paths; ++p) {
    const uint32_t n = launch.target_counts[p] < kNeuralPathTargets ? launch.target_counts[p] : kNeuralPathTargets;
    for (uint32_t k = 0; k < n; ++k) {
      if (kept < t.room)  // the tile's capacity (a room smaller than it is never outgrown)
        out[kept++] = launch.targets[p * kNeuralPathTargets + k];
      else
        ++dropped;
    }
  }
  launch.tile_target_counts[tile] = kept;
  launch.tile_target_counts[launch.num_tiles + tile] = dropped;
}

}  // namespace tessera
