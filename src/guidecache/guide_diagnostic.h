// The seed thesis' diagnostic render of a learned guide: every path follows,
// at each vertex, the bin with the largest Q max(cos, 0), and shows what it
// finds: a light it runs into, or at its last vertex the reflected radiance
// the guide learned there (rho/pi times the cell's learned irradiance; with
// NEE the field holds the radiance NEE does not deliver, so greedy paths run
// to brightly lit surfaces rather than to the lights). Where a path ends in
// darkness, the guide points nowhere useful. Not an estimator of anything.
#pragma once

#include "kernels/effects.h"
#include "kernels/light_sampling.h"
#include "kernels/material_eval.h"
#include "kernels/surface.h"

namespace tessera {

// PathGuide: TablePathGuide or NeuralPathGuide (path_guide.h).
template <class PathGuide, class Tracer>
TESSERA_HOST_DEVICE Rgb trace_greedy_path(const SceneView& s, PathGuide& g, const Tracer& tracer, Ray ray,
                                          int32_t max_depth) {
  constexpr uint32_t kSpec = kSpecSurfaceAll & ~kSpecGuiding;
  Rgb beta(1.f);
  int32_t interface_skips = 0;
  for (int32_t depth = 0;; ++depth) {
    TraceHit hit;
    if (!tracer.intersect(ray.o, ray.d, kInfinity, &hit)) {
      Rgb Le(0.f);
      for (uint32_t k = 0; k < s.num_infinite_lights; ++k)
        Le += environment_radiance(s, s.lights[s.infinite_lights[k]], ray.o, ray.d);
      return beta * Le;
    }
    const RayPoint from_ray{ray.o, ray.d, hit.t};
    SurfaceHit h = make_surface_hit(s, hit, 0.f, &from_ray);
    Vec3 wo = -ray.d;
    const TriangleInfo& info = s.triangles[hit.triangle];
    if (info.light >= 0) {
      const Light& l = s.lights[info.light];
      if (l.two_sided || glm::dot(h.ng, wo) > 0.f) return beta * area_light_radiance(s, l, h.uv);
    }
    BsdfParams bsdf;
    if (!resolve_bsdf<kSpec>(s, info.material, h, wo, &bsdf)) {
      // Through an interface without a bounce (as the integrator), a bounded number of times.
      if (++interface_skips > 256) return Rgb(0.f);
      ray.o = offset_ray_origin(h, ray.d);
      --depth;
      continue;
    }
    Vec3 n_side = glm::dot(h.ng, wo) >= 0.f ? h.ng : -h.ng;
    int32_t cell = g.locate(h.p, n_side);
    Float best = 0.f;
    uint32_t best_bin = 0;
    for (uint32_t j = 0; j < g.bins(); ++j) {
      const Float c = glm::dot(g.bin_dir(j), n_side);
      if (!(c > 0.f)) continue;  // adds nothing (and a network's Q below the surface need not be computed)
      const Float v = g.value(cell, j) * c;
      if (v > best) {
        best = v;
        best_bin = j;
      }
    }
    // Shade with the albedo-like reflectance so materials stay recognisable.
    beta *= bsdf.type == BsdfType::Diffuse || bsdf.type == BsdfType::CoatedDiffuse ? bsdf.reflectance : Rgb(1.f);
    if (!(best > 0.f) || depth >= max_depth) return beta * (kInvPi * g.irradiance(cell));
    ray.d = g.bin_dir(best_bin);
    ray.o = offset_ray_origin(h, ray.d);
  }
}

}  // namespace tessera
