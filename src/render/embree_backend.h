// The Embree backend: one Embree scene holding the world's triangles and an
// Embree instance per object instance (one scene per prototype), traced by
// this process's threads. Integrators only see EmbreeTracer's
// intersect/occluded (see integrator/integrator.h); the pass loop only sees
// EmbreeBackend as a TileBackend (render/tile_backend.h).
#pragma once

#include <embree3/rtcore.h>

#include <memory>
#include <string>
#include <vector>

#include "integrator/integrator.h"
#include "kernels/ray_guard.h"
#include "render/cpu_tile_backend.h"
#include "render/scene_data.h"

namespace tessera {

struct EmbreeTracer {
  RTCScene scene = nullptr;
  // Where rays this tracer refuses are counted (kernels/ray_guard.h); null: not counted.
  uint64_t* untraceable = nullptr;
  // Per instance, its prototype's first triangle: a hit's primID counts from there.
  const uint32_t* instance_first = nullptr;

  // time: where in the transform interval, for moving shapes (0..1).
  // Always inline: a call would take the address of the path state's ray
  // and keep the integrator's state out of registers (docs/development.md).
  TESSERA_INLINE bool intersect(const Vec3& o, const Vec3& d, Float tmax, TraceHit* hit, Float time = 0.f) const {
    if (!ray_traceable(o, d, tmax)) return refuse_ray(untraceable, false);
    RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    ctx.flags = RTC_INTERSECT_CONTEXT_FLAG_INCOHERENT;
    RTCRayHit rh;
    rh.ray.org_x = o.x; rh.ray.org_y = o.y; rh.ray.org_z = o.z;
    rh.ray.dir_x = d.x; rh.ray.dir_y = d.y; rh.ray.dir_z = d.z;
    rh.ray.tnear = 0.f;
    rh.ray.tfar = tmax;
    rh.ray.time = time;
    rh.ray.mask = 0xffffffffu;
    rh.ray.id = 0;
    rh.ray.flags = 0;
    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
    rtcIntersect1(scene, &ctx, &rh);
    if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return false;
    hit->t = rh.ray.tfar;
    hit->triangle = rh.hit.primID;
    hit->instance = -1;
    if (rh.hit.instID[0] != RTC_INVALID_GEOMETRY_ID) {
      hit->instance = static_cast<int32_t>(rh.hit.instID[0]) - 1;
      hit->triangle += instance_first[hit->instance];
    }
    hit->b1 = rh.hit.u;
    hit->b2 = rh.hit.v;
    return true;
  }

  TESSERA_INLINE bool occluded(const Vec3& o, const Vec3& d, Float tmax, Float time = 0.f) const {
    if (!ray_traceable(o, d, tmax)) return refuse_ray(untraceable, true);
    RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    ctx.flags = RTC_INTERSECT_CONTEXT_FLAG_INCOHERENT;
    RTCRay r;
    r.org_x = o.x; r.org_y = o.y; r.org_z = o.z;
    r.dir_x = d.x; r.dir_y = d.y; r.dir_z = d.z;
    r.tnear = 0.f;
    r.tfar = tmax;
    r.time = time;
    r.mask = 0xffffffffu;
    r.id = 0;
    r.flags = 0;
    rtcOccluded1(scene, &ctx, &r);
    return r.tfar < 0.f;  // Embree sets tfar = -inf on a hit
  }
};

class EmbreeScene {
 public:
  // `data` must outlive this scene: alpha cutouts read its view from Embree's filter.
  explicit EmbreeScene(const SceneData& data);
  ~EmbreeScene();
  EmbreeScene(const EmbreeScene&) = delete;
  EmbreeScene& operator=(const EmbreeScene&) = delete;
  EmbreeTracer tracer() const { return EmbreeTracer{scene_, nullptr, instance_first_.data()}; }

  // What the hit filter reads for one geometry: triangle primID of it is
  // triangle first_triangle + primID of the view.
  struct FilterData {
    const SceneView* view;
    uint32_t first_triangle;
  };

 private:
  void build(const SceneData& data);
  RTCScene new_scene();
  void attach_triangles(const SceneData& data, RTCScene scene, uint32_t first, uint32_t count, unsigned id);
  void attach_instance(const ObjectInstance& inst, unsigned id);
  [[noreturn]] void fail(const std::string& what) const;
  void release();  // the Embree handles (constructor failure and destructor)
  std::string error_;  // first error Embree reported
  RTCDevice device_ = nullptr;
  RTCScene scene_ = nullptr;
  std::vector<RTCScene> prototypes_;  // one per prototype (kernels/instance.h)
  std::vector<uint32_t> instance_first_;
  std::vector<std::unique_ptr<FilterData>> filters_;
};

// Adds samples [sample_begin, sample_end) of every pixel of the job to its
// accumulators, in sample order, with the integrator specialisation
// settings.specialisation names. Random streams depend on (seed, pixel
// index in the whole image, sample index) only, so a tile renders the same
// wherever it runs. With light-traced caustics
// (settings.path.light_traced_caustics) each sample also traces one light
// path, whose contributions to any pixel of the image are appended to
// *splats in order (film_add_splats adds them, tile by tile in job order).
TileCounters render_tile(const SceneView& scene, const EmbreeTracer& tracer, const TileSettings& settings,
                         const TileJob& job, TilePixels pixels, std::vector<Splat>* splats = nullptr);

class EmbreeBackend : public CpuTileBackend {
 public:
  // `data` must outlive the backend.
  explicit EmbreeBackend(const SceneData& data) : view_(data.view()), scene_(data) {}
  std::string name() const override { return "embree"; }
  // Ray queries for tools that trace rays of their own (guide-viz, bench-rays).
  EmbreeTracer tracer() const { return scene_.tracer(); }

 protected:
  TileCounters render_one(const TileSettings& settings, const TileJob& job, TilePixels pixels,
                          std::vector<Splat>* splats) const override {
    return render_tile(view_, scene_.tracer(), settings, job, pixels, splats);
  }

 private:
  const SceneView& view_;
  EmbreeScene scene_;
};

}  // namespace tessera
