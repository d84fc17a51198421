// The device API emulated on the host (render/device_api.h): "device"
// memory is this process's, and a launch runs the CUDA kernels' bodies
// (render/device_tiles.h) on a oneTBB arena, in the same two steps. It exists so that
// the device backend's batching, scene packing, guide upload and
// accumulator return are tested wherever the suite runs.
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>

#include "render/host_memory_device.h"

namespace tessera {
namespace {

template <uint32_t Spec>
void run_launch(const DeviceLaunch& launch, tbb::task_arena& arena) {
  arena.execute([&] {
    const uint64_t steps = uint64_t{launch.num_tiles} * launch.max_samples;
    tbb::parallel_for(uint64_t{0}, steps, [&](uint64_t i) {
      const uint32_t tile = static_cast<uint32_t>(i / launch.max_samples), sample = static_cast<uint32_t>(i % launch.max_samples);
      for (uint32_t p = 0; p < launch.max_tile_pixels; ++p) trace_device_sample<Spec>(launch, tile, p, sample);
    });
    tbb::parallel_for(uint32_t{0}, launch.num_tiles, [&](uint32_t tile) {
      for (uint32_t p = 0; p < launch.max_tile_pixels; ++p) accumulate_device_pixel(launch, tile, p);
      gather_device_targets(launch, tile);
    });
  });
}

class EmulatedDevice : public HostMemoryDevice {
 public:
  explicit EmulatedDevice(int32_t threads) : arena_(std::max(1, threads)) {}
  std::string backend_name() const override { return "emulated-device"; }
  std::string description() const override { return "the device kernel on host threads"; }
  bool has_media_kernels() const override { return true; }
  // Runs the launch to its end: the emulation has nothing to overlap.
  void start(const DeviceLaunch& launch, uint32_t spec) override {
    dispatch_served(spec, [&](auto served) { run_launch<decltype(served)::value>(launch, arena_); });
  }

 private:
  tbb::task_arena arena_;
};

}  // namespace

std::unique_ptr<DeviceApi> open_emulated_device(int32_t threads) { return std::make_unique<EmulatedDevice>(threads); }

}  // namespace tessera
