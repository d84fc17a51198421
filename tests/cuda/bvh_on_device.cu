// The portable BVH's traversal (kernels/bvh.h) built by nvcc and run on the
// GPU must find what the host build finds: closest hits (triangle and
// distance) and shadow-ray answers for random rays through a scene of
// random triangles and a tessellated sphere. Also prints rays per second on
// the device and on one host core.
// Not GoogleTest (host-only); exits 0 when all agree, 1 on a failure, 77
// (CTest's skip) without a device.
#include <cuda_runtime.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <vector>

#include "kernels/bvh.h"
#include "kernels/rng.h"
#include "kernels/sampling.h"
#include "render/bvh_build.h"

#include "cuda_check.h"

using namespace tessera;
using cuda_check::to_device;

namespace {

constexpr int kRays = 1 << 20;

__global__ void trace_kernel(BvhView bvh, const SceneView* scene, const Vec3* o, const Vec3* d, int n, TraceHit* hits,
                             int* found, int* occluded) {
  const int i = blockIdx.x * blockDim.x + threadIdx.x;
  if (i >= n) return;
  const BvhTracer t{bvh, scene};
  TraceHit h{};
  found[i] = t.intersect(o[i], d[i], kInfinity, &h) ? 1 : 0;
  hits[i] = h;
  // Short of the closest hit (free) and past it (blocked).
  occluded[i] = (t.occluded(o[i], d[i], found[i] ? 0.5f * h.t : 100.f) ? 1 : 0) +
                (found[i] && t.occluded(o[i], d[i], 2.f * h.t) ? 2 : 0);
}


// 200k random small triangles in a 10-unit cube and a sphere of 64 x 128 quads.
struct Scene {
  std::vector<Vec3> positions, face_normals;
  std::vector<uint32_t> indices;
  std::vector<TriangleInfo> triangles;
  SceneView view() const {
    SceneView v;
    v.positions = positions.data();
    v.indices = indices.data();
    v.triangles = triangles.data();
    v.face_normals = face_normals.data();
    v.num_triangles = static_cast<uint32_t>(triangles.size());
    return v;
  }
};

Scene make_scene() {
  Scene s;
  Rng rng = Rng::for_sample(11, 0, 0);
  for (int t = 0; t < 200000; ++t) {
    const Vec3 c = Vec3(rng.uniform(), rng.uniform(), rng.uniform()) * 10.f - 5.f;
    for (int k = 0; k < 3; ++k) {
      s.indices.push_back(static_cast<uint32_t>(s.positions.size()));
      s.positions.push_back(c + 0.1f * (Vec3(rng.uniform(), rng.uniform(), rng.uniform()) - 0.5f));
    }
  }
  const int rings = 64, segs = 128;
  const uint32_t base = static_cast<uint32_t>(s.positions.size());
  for (int i = 0; i <= rings; ++i)
    for (int j = 0; j <= segs; ++j) {
      const float th = 3.14159265f * i / rings, ph = 6.2831853f * j / segs;
      s.positions.push_back(2.f * Vec3(std::sin(th) * std::cos(ph), std::sin(th) * std::sin(ph), std::cos(th)));
    }
  for (int i = 0; i < rings; ++i)
    for (int j = 0; j < segs; ++j) {
      const uint32_t a = base + i * (segs + 1) + j, b = a + 1, c = a + segs + 2, d = a + segs + 1;
      for (uint32_t v : {a, b, c, a, c, d}) s.indices.push_back(v);
    }
  const size_t n = s.indices.size() / 3;
  s.triangles.resize(n);
  for (size_t t = 0; t < n; ++t) {
    Vec3 nrm(0.f, 0.f, 1.f);
    triangle_normal(s.positions[s.indices[3 * t]], s.positions[s.indices[3 * t + 1]], s.positions[s.indices[3 * t + 2]],
                    &nrm, nullptr);
    s.face_normals.push_back(nrm);
  }
  return s;
}

}  // namespace

int main() {
  if (!cuda_check::device_present()) return 77;
  const Scene scene = make_scene();
  const SceneView view = scene.view();
  const BvhBuild build = build_bvh(view);
  std::printf("scene: %u triangles, bvh %zu nodes, depth %d\n", view.num_triangles, build.nodes.size(), build.depth);

  std::vector<Vec3> o(kRays), d(kRays);
  Rng rng = Rng::for_sample(5, 0, 0);
  for (int i = 0; i < kRays; ++i) {
    o[i] = Vec3(rng.uniform(), rng.uniform(), rng.uniform()) * 12.f - 6.f;
    d[i] = sample_uniform_sphere(rng.uniform2());
  }
  // Host: one core.
  std::vector<TraceHit> host(kRays);
  std::vector<int> host_found(kRays), host_occluded(kRays);
  const BvhTracer ht{build.view(), &view};
  const auto h0 = std::chrono::steady_clock::now();
  for (int i = 0; i < kRays; ++i) {
    host[i] = TraceHit{};
    host_found[i] = ht.intersect(o[i], d[i], kInfinity, &host[i]) ? 1 : 0;
    host_occluded[i] = (ht.occluded(o[i], d[i], host_found[i] ? 0.5f * host[i].t : 100.f) ? 1 : 0) +
                       (host_found[i] && ht.occluded(o[i], d[i], 2.f * host[i].t) ? 2 : 0);
  }
  const double host_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - h0).count();

  // Device: the scene's arrays, the view pointing at them, the BVH.
  SceneView dview;
  dview.positions = to_device(scene.positions);
  dview.indices = to_device(scene.indices);
  dview.triangles = to_device(scene.triangles);
  dview.face_normals = to_device(scene.face_normals);
  dview.num_triangles = view.num_triangles;
  SceneView* dscene = nullptr;
  cudaMalloc(&dscene, sizeof(SceneView));
  cudaMemcpy(dscene, &dview, sizeof(SceneView), cudaMemcpyHostToDevice);
  BvhView dbvh{to_device(build.nodes), to_device(build.triangles), static_cast<uint32_t>(build.nodes.size()),
               static_cast<uint32_t>(build.triangles.size())};
  Vec3* d_o = to_device(o);
  Vec3* d_d = to_device(d);
  TraceHit* d_hits = nullptr;
  int *d_found = nullptr, *d_occluded = nullptr;
  cudaMalloc(&d_hits, kRays * sizeof(TraceHit));
  cudaMalloc(&d_found, kRays * sizeof(int));
  cudaMalloc(&d_occluded, kRays * sizeof(int));
  trace_kernel<<<(kRays + 127) / 128, 128>>>(dbvh, dscene, d_o, d_d, kRays, d_hits, d_found, d_occluded);  // warm-up
  if (!cuda_check::ok(cudaDeviceSynchronize(), "trace_kernel")) return 1;
  cudaEvent_t e0, e1;
  cudaEventCreate(&e0);
  cudaEventCreate(&e1);
  cudaEventRecord(e0);
  constexpr int kRepeats = 10;
  for (int r = 0; r < kRepeats; ++r)
    trace_kernel<<<(kRays + 127) / 128, 128>>>(dbvh, dscene, d_o, d_d, kRays, d_hits, d_found, d_occluded);
  cudaEventRecord(e1);
  if (!cuda_check::ok(cudaEventSynchronize(e1), "timing")) return 1;
  float ms = 0.f;
  cudaEventElapsedTime(&ms, e0, e1);
  std::vector<TraceHit> dev(kRays);
  std::vector<int> dev_found(kRays), dev_occluded(kRays);
  cudaMemcpy(dev.data(), d_hits, kRays * sizeof(TraceHit), cudaMemcpyDeviceToHost);
  cudaMemcpy(dev_found.data(), d_found, kRays * sizeof(int), cudaMemcpyDeviceToHost);
  cudaMemcpy(dev_occluded.data(), d_occluded, kRays * sizeof(int), cudaMemcpyDeviceToHost);

  int hits = 0, differ = 0, occlusion_differ = 0;
  for (int i = 0; i < kRays; ++i) {
    hits += host_found[i];
    const bool same = host_found[i] == dev_found[i] &&
                      (!host_found[i] || host[i].triangle == dev[i].triangle ||
                       std::fabs(host[i].t - dev[i].t) <= 1e-5f * std::fmax(1.f, host[i].t));
    differ += !same;
    occlusion_differ += host_occluded[i] != dev_occluded[i];
  }
  // Each ray is a closest-hit query plus a shadow query.
  const double dev_rays_s = 2.0 * kRays * kRepeats / (ms * 1e-3), host_rays_s = 2.0 * kRays / host_s;
  cudaDeviceProp prop{};
  cudaGetDeviceProperties(&prop, 0);
  std::printf("device: %s\n", prop.name);
  std::printf("bvh: %d rays, %d hits, %d differ from the host, %d shadow answers differ\n", kRays, hits, differ,
              occlusion_differ);
  std::printf("bvh: %.1f Mrays/s on the device, %.2f Mrays/s on one host core (%.0fx)\n", dev_rays_s * 1e-6,
              host_rays_s * 1e-6, dev_rays_s / host_rays_s);
  // nvcc contracts multiply-adds: a ray through an edge may pick the neighbour; a tiny counted fraction.
  const bool pass = hits > kRays / 4 && differ <= kRays / 10000 && occlusion_differ <= kRays / 10000;
  std::printf("%s\n", pass ? "bvh traversal agrees with the host" : "FAILED");
  return pass ? 0 : 1;
}
