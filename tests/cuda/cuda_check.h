// Small helpers the GPU check programs share (they are not GoogleTest).
#pragma once

#include <cuda_runtime.h>

#include <cstdio>
#include <vector>

namespace tessera::cuda_check {

// Whether a CUDA device is present; prints the skip line when not (the
// programs then exit 77, CTest's skip).
inline bool device_present() {
  int devices = 0;
  if (cudaGetDeviceCount(&devices) == cudaSuccess && devices > 0) return true;
  std::printf("skip: no CUDA device\n");
  return false;
}

// Prints a failure line for a CUDA error; true when there was none.
inline bool ok(cudaError_t e, const char* what) {
  if (e == cudaSuccess) return true;
  std::printf("FAIL %s: %s\n", what, cudaGetErrorString(e));
  return false;
}

// A device copy of v (freed by the process's exit).
template <class T>
T* to_device(const std::vector<T>& v) {
  T* d = nullptr;
  cudaMalloc(&d, v.size() * sizeof(T));
  cudaMemcpy(d, v.data(), v.size() * sizeof(T), cudaMemcpyHostToDevice);
  return d;
}

}  // namespace tessera::cuda_check
