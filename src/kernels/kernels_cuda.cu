// Compiles the device-agnostic kernels with nvcc, so that every change to
// src/kernels/ is checked against the CUDA compiler whenever nvcc exists.
// The GPU backend (a later issue) provides a real ray-query type in place of
// NoGeometryTracer; the integrator code is the same.
#include "kernels/integrator.h"

namespace tessera {

// Ray queries against an empty scene: enough to instantiate the integrator.
struct NoGeometryTracer {
  __device__ bool intersect(const Vec3&, const Vec3&, Float, TraceHit*, Float = 0.f) const { return false; }
  __device__ bool occluded(const Vec3&, const Vec3&, Float, Float = 0.f) const { return false; }
};

template <uint32_t Spec>
__global__ void trace_pixels_kernel(SceneView scene, PathSettings settings, SamplerSetup sampler, Rgb* out) {
  const int32_t x = blockIdx.x * blockDim.x + threadIdx.x;
  const int32_t y = blockIdx.y * blockDim.y + threadIdx.y;
  if (x >= scene.camera.width || y >= scene.camera.height) return;
  const uint64_t pixel = static_cast<uint64_t>(y) * scene.camera.width + x;
  PixelSampler rng = PixelSampler::start(sampler, static_cast<uint32_t>(x), static_cast<uint32_t>(y), pixel, 0);
  const CameraSample cs = sample_camera_ray(scene, x, y, rng);
  PathCounters counters;
  out[pixel] = film_pixel_value(scene.camera, trace_path<Spec>(scene, NoGeometryTracer{}, cs.ray, rng, settings, counters)) *
               cs.filter_weight;
}

// Instantiate the lean and the full specialisation.
template __global__ void trace_pixels_kernel<0u>(SceneView, PathSettings, SamplerSetup, Rgb*);
template __global__ void trace_pixels_kernel<kSpecAll>(SceneView, PathSettings, SamplerSetup, Rgb*);

}  // namespace tessera
