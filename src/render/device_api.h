// What the device backend (render/device_backend.h) asks of a device:
// memory, copies and one launch per batch of tiles. Two implementations:
// CUDA (render/cuda_device.cu, where the build has nvcc) and a host
// emulation (render/host_device.cpp) that runs the same kernel body on this
// process's threads, so everything of the GPU path but the CUDA calls
// themselves is tested on machines without a GPU. No CUDA type here.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>

#include "render/device_tiles.h"

namespace tessera {

class DeviceApi {
 public:
  virtual ~DeviceApi() = default;
  // The backend's name in the log and stats: cuda, or emulated-device.
  virtual std::string backend_name() const = 0;
  // What the device is (model, memory), for the log.
  virtual std::string description() const = 0;
  // Whether it has the media kernels (served_specialisation with kSpecMedia).
  virtual bool has_media_kernels() const = 0;
  // Device memory; every call throws std::runtime_error on failure.
  virtual void* alloc(size_t bytes) = 0;
  virtual void release(void* p) noexcept = 0;
  virtual void upload(void* device_dst, const void* host_src, size_t bytes) = 0;
  virtual void download(void* host_dst, const void* device_src, size_t bytes) = 0;
  virtual void zero(void* device_dst, size_t bytes) = 0;
  // Starts rendering every sample of every tile of the launch (trace, then
  // accumulate and gather_device_targets per tile) with the integrator served_specialisation(spec) names. The
  // caller polls finished() (the farm master answers its workers meanwhile)
  // and then calls wait(), which reports the launch's errors.
  virtual void start(const DeviceLaunch& launch, uint32_t spec) = 0;
  virtual bool finished() = 0;
  virtual void wait() = 0;
};

// How many CUDA devices there are (no context is made); 0 with *why saying
// why not (no device or driver, or a build without nvcc).
int cuda_device_count(std::string* why);
// A CUDA device, or null with *why saying why not. Ranks of a farm on one
// machine take devices in turn (their local rank, modulo the count).
std::unique_ptr<DeviceApi> open_cuda_device(std::string* why);
// The kernel body on `threads` host threads, memory in this process.
std::unique_ptr<DeviceApi> open_emulated_device(int32_t threads);

}  // namespace tessera
