// The one place that knows whether code is being compiled for the GPU.
// Everything in src/kernels/ marks shared functions with TESSERA_HOST_DEVICE
// and includes nothing that nvcc cannot compile (no std containers, no
// exceptions, no Embree/OpenEXR/MPI/cereal).
#pragma once

#if defined(__CUDACC__)
#define TESSERA_HOST_DEVICE __host__ __device__
#define TESSERA_INLINE __forceinline__
// A large function called from many places: one copy in the device code,
// not one per call site (ptxas time grows faster than the kernel's size).
// Also a large path that few samples take (layered BSDFs, hair, guide
// learning, spectral transport), as Cycles keeps such code out of line
// (ccl_device_noinline): ptxas compiles it apart, and the hot loop's
// registers are not allocated around it. On the host it is plain inline.
#define TESSERA_DEVICE_NOINLINE __noinline__
// Cold code of the integrator's stages: out of line on the GPU as above,
// always inline on the CPU, where a call would take the address of the
// caller's path state and keep it out of registers (docs/development.md).
#define TESSERA_COLD_STAGE __noinline__
// Cold code taking only values (never the address of the caller's path
// state): out of line on both, so the hot loop's registers are not
// allocated around it.
#define TESSERA_NOINLINE __noinline__ inline
#else
#define TESSERA_HOST_DEVICE
#define TESSERA_INLINE inline __attribute__((always_inline))
#define TESSERA_DEVICE_NOINLINE
#define TESSERA_COLD_STAGE inline __attribute__((always_inline))
#define TESSERA_NOINLINE inline __attribute__((noinline))
#endif

// TESSERA_PREFETCH hints that memory will be read soon: a no-op on the GPU,
// whose caches are fed by other warps while one waits.
#if defined(__CUDA_ARCH__)
#define TESSERA_IS_GPU_CODE 1
#define TESSERA_PREFETCH(p) ((void)(p))
#else
#define TESSERA_IS_GPU_CODE 0
#define TESSERA_PREFETCH(p) __builtin_prefetch(p)
#endif

#define GLM_FORCE_XYZW_ONLY
#include <glm/glm.hpp>

#include <cstdint>

namespace tessera {

// float is deliberate for everything that travels along a path: it is what
// Embree traces with and what the GPU is fast at. Pixel accumulation uses double
// (see src/render/film.h).
using Float = float;
using Vec2 = glm::vec2;
using Vec3 = glm::vec3;
using Vec4 = glm::vec4;
using Mat3 = glm::mat3;
using Mat4 = glm::mat4;
using Rgb = glm::vec3;  // linear sRGB radiance / reflectance

constexpr Float kPi = 3.14159265358979323846f;
constexpr Float kInvPi = 0.31830988618379067154f;
constexpr Float kInv2Pi = 0.15915494309189533577f;
constexpr Float kInv4Pi = 0.07957747154594766788f;
// The largest float: "no hit" distance of a ray (finite, so 0 * kInfinity is 0).
constexpr Float kInfinity = 3.402823466e+38f;

// Relaxed atomic add, for order-independent integer accumulators (sums come
// out bit-identical whatever the thread or block order). Signed values are
// added as their two's-complement bits.
TESSERA_HOST_DEVICE inline void atomic_add_u64(uint64_t* p, uint64_t v) {
#if TESSERA_IS_GPU_CODE
  atomicAdd(reinterpret_cast<unsigned long long*>(p), static_cast<unsigned long long>(v));
#else
  __atomic_fetch_add(p, v, __ATOMIC_RELAXED);
#endif
}

}  // namespace tessera
