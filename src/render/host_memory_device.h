// The part of a DeviceApi that devices running on the host share: their
// "device" memory is this process's, and their launches end before start()
// returns (nothing to overlap). The emulated device (host_device.cpp) and
// the GPU check's host threads (tests/cuda/device_backend_on_device.cpp)
// add only their launches.
#pragma once

#include <cstdlib>
#include <cstring>
#include <new>

#include "render/device_api.h"

namespace tessera {

class HostMemoryDevice : public DeviceApi {
 public:
  void* alloc(size_t bytes) override {
    void* p = std::aligned_alloc(64, (bytes + 63) & ~size_t{63});
    if (!p) throw std::bad_alloc();
    return p;
  }
  void release(void* p) noexcept override { std::free(p); }
  void upload(void* dst, const void* src, size_t bytes) override { std::memcpy(dst, src, bytes); }
  void download(void* dst, const void* src, size_t bytes) override { std::memcpy(dst, src, bytes); }
  void zero(void* dst, size_t bytes) override { std::memset(dst, 0, bytes); }
  bool finished() override { return true; }
  void wait() override {}
};

}  // namespace tessera
