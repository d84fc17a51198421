// The CPU ray-query backend: one Embree scene holding every triangle.
// Integrators only see EmbreeTracer's intersect/occluded (see kernels/integrator.h).
#pragma once

#include <embree3/rtcore.h>

#include <string>

#include "kernels/integrator.h"
#include "worker/scene_data.h"

namespace tessera {

struct EmbreeTracer {
  RTCScene scene = nullptr;

  // time: where in the transform interval, for moving shapes (0..1).
  bool intersect(const Vec3& o, const Vec3& d, Float tmax, TraceHit* hit, Float time = 0.f) const {
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
    hit->b1 = rh.hit.u;
    hit->b2 = rh.hit.v;
    return true;
  }

  bool occluded(const Vec3& o, const Vec3& d, Float tmax, Float time = 0.f) const {
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
  EmbreeTracer tracer() const { return EmbreeTracer{scene_}; }

 private:
  void build(const SceneData& data);
  void release();  // the Embree handles (constructor failure and destructor)
  std::string error_;  // first error Embree reported
  RTCDevice device_ = nullptr;
  RTCScene scene_ = nullptr;
};

}  // namespace tessera
