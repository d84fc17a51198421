// open_cuda_device for builds without nvcc (the CUDA one is in cuda_device.cu).
#include "render/device_api.h"

#if !TESSERA_HAVE_CUDA
namespace tessera {

int cuda_device_count(std::string* why) {
  if (why) *why = "this build has no CUDA backend (nvcc was not found when it was built)";
  return 0;
}

std::unique_ptr<DeviceApi> open_cuda_device(std::string* why) {
  cuda_device_count(why);
  return nullptr;
}

}  // namespace tessera
#endif
