// The portable-BVH backend on the CPU: the traversal the GPU runs
// (kernels/bvh.h), traced by this process's threads. It is how the GPU's
// ray queries are tested on machines without one. Served by the full
// integrator whatever the tile settings' specialisation narrows
// (served_specialisation in render/device_tiles.h), as on the GPU. Statistically the same image as Embree,
// not bit for bit (docs/farm.md).
#pragma once

#include "kernels/bvh.h"
#include "render/bvh_build.h"
#include "render/cpu_tile_backend.h"
#include "render/scene_data.h"

namespace tessera {

TileCounters render_tile(const SceneView& scene, const BvhTracer& tracer, const TileSettings& settings,
                         const TileJob& job, TilePixels pixels, std::vector<Splat>* splats = nullptr);

class BvhBackend : public CpuTileBackend {
 public:
  // `data` must outlive the backend.
  explicit BvhBackend(const SceneData& data)
      : view_(data.view()), build_(build_bvh(data.view())), tracer_{build_.view(), &data.view()} {}
  std::string name() const override { return "bvh"; }
  bool serves_full_integrator() const override { return true; }
  const BvhTracer& tracer() const { return tracer_; }
  const BvhBuild& build() const { return build_; }

 protected:
  TileCounters render_one(const TileSettings& settings, const TileJob& job, TilePixels pixels,
                          std::vector<Splat>* splats) const override {
    return render_tile(view_, tracer_, settings, job, pixels, splats);
  }

 private:
  const SceneView& view_;
  BvhBuild build_;
  BvhTracer tracer_;
};

}  // namespace tessera
