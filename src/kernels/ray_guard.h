// Which rays the tracers take. Embree 3 refuses a ray whose origin or
// direction has a component beyond +-1.844e18 (its FLT_LARGE) or NaN, or
// whose tnear or tfar is NaN (RayK::valid()), and its assertion aborts the
// process: every rank of a farm with it. Every tracer (Embree's, the
// portable BVH's on the CPU and on the device) asks ray_traceable first and
// answers a ray it does not take itself: a miss for intersect, occluded for
// occluded (no light arrives along a ray that cannot be traced), counted in
// PathCounters::untraceable_rays (the stats JSON's "untraceable_rays").
//
// Scenes keep their coordinates within +-kMaxSceneCoordinate (vertices,
// camera rays, lights: checked at load), under the tracer's limit with room
// for a ray offset; rays beyond it start where nothing can be hit: at
// scattering points far out in an unbounded medium of very thin density.
#pragma once

#include "vecmath.h"

namespace tessera {

constexpr Float kMaxRayComponent = 1.844e18f;   // Embree 3's FLT_LARGE
constexpr Float kMaxSceneCoordinate = 1e18f;    // what a scene file may place

// Whether every component of v is within +-limit (false for NaN).
TESSERA_HOST_DEVICE inline bool within(const Vec3& v, Float limit) {
  return fabsf(v.x) <= limit && fabsf(v.y) <= limit && fabsf(v.z) <= limit;
}

// Whether a tracer takes the ray from o along d up to tmax (from 0).
TESSERA_HOST_DEVICE inline bool ray_traceable(const Vec3& o, const Vec3& d, Float tmax) {
  return within(o, kMaxRayComponent) && within(d, kMaxRayComponent) && tmax == tmax;
}

// A tracer's answer for a ray it does not take, counted where the tracer has a counter.
TESSERA_HOST_DEVICE inline bool refuse_ray(uint64_t* counter, bool answer) {
  if (counter) ++*counter;
  return answer;
}

}  // namespace tessera
