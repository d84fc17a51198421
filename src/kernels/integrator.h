// Unidirectional path tracing with next-event estimation and MIS (power
// heuristic), Russian roulette, pbrt-v4's depth counting. Templated on the
// scene's specialisation bits (effects.h) and on the ray-query backend, which
// provides:
//   bool intersect(const Vec3& o, const Vec3& d, Float tmax, TraceHit* hit) const;
//   bool occluded(const Vec3& o, const Vec3& d, Float tmax) const;   // d unit length
#pragma once

#include "bsdf.h"
#include "camera.h"
#include "effects.h"
#include "light_sampling.h"
#include "material_eval.h"
#include "rng.h"

namespace tessera {

struct TraceHit {
  Float t;
  uint32_t triangle;
  Float b1, b2;  // barycentrics of vertices 1 and 2
};

constexpr Float kInfinity = 3.402823466e+38f;

// Per-path counters; summed over a tile with integer adds (order-independent).
struct PathCounters {
  uint64_t rays = 0;          // closest-hit queries
  uint64_t shadow_rays = 0;   // occlusion queries
  uint64_t vertices = 0;      // surface interactions along paths
  uint64_t interface_skips = 0;
};

struct PathSettings {
  int32_t max_depth = 5;
  bool nee = true;  // false: emitters are found by BSDF sampling only (for tests and comparisons)
};

namespace detail {

// Lambertian fast path used when the scene has no other BSDF.
TESSERA_HOST_DEVICE inline Rgb diffuse_eval(const BsdfParams& b, const Vec3& wo, const Vec3& wi) {
  return same_hemisphere(wo, wi) ? b.reflectance * kInvPi : Rgb(0.f);
}

}  // namespace detail

template <uint32_t Spec>
TESSERA_HOST_DEVICE inline Rgb eval_f(const BsdfParams& b, const Vec3& wo, const Vec3& wi) {
  if constexpr ((Spec & kSpecNonDiffuse) != 0) return bsdf_eval(b, wo, wi);
  else return detail::diffuse_eval(b, wo, wi);
}
template <uint32_t Spec>
TESSERA_HOST_DEVICE inline Float eval_pdf(const BsdfParams& b, const Vec3& wo, const Vec3& wi) {
  if constexpr ((Spec & kSpecNonDiffuse) != 0) return bsdf_pdf(b, wo, wi);
  else return same_hemisphere(wo, wi) ? abs_cos_theta(wi) * kInvPi : 0.f;
}
template <uint32_t Spec>
TESSERA_HOST_DEVICE inline bool sample_f(const BsdfParams& b, const Vec3& wo, Float uc, Vec2 u, BsdfSample* bs) {
  if constexpr ((Spec & kSpecNonDiffuse) != 0) {
    return bsdf_sample(b, wo, uc, u, bs);
  } else {
    (void)uc;
    Vec3 wi = sample_cosine_hemisphere(u);
    if (wo.z < 0.f) wi.z = -wi.z;
    if (wi.z == 0.f) return false;
    bs->wi = wi;
    bs->pdf = abs_cos_theta(wi) * kInvPi;
    bs->f = b.reflectance * kInvPi;
    bs->lobe = kLobeReflection | kLobeDiffuse;
    bs->eta = 1.f;
    return bs->pdf > 0.f;
  }
}

// Radiance arriving along the ray; consumes random numbers from rng in a fixed order.
template <uint32_t Spec, class Tracer>
TESSERA_HOST_DEVICE Rgb trace_path(const SceneView& s, const Tracer& tracer, Ray ray, Rng& rng,
                                   const PathSettings& settings, PathCounters& c) {
  Rgb L(0.f), beta(1.f);
  int32_t depth = 0;
  bool specular_bounce = false;
  Float prev_bsdf_pdf = 0.f;
  Vec3 prev_p(0.f);  // last scattering point: MIS on emitter hits measures from it, as NEE does
  Float eta_scale = 1.f;
  int32_t interface_skips = 0;

  for (;;) {
    TraceHit hit;
    ++c.rays;
    if (!tracer.intersect(ray.o, ray.d, kInfinity, &hit)) {
      if constexpr ((Spec & kSpecEnvironment) != 0) {
        for (uint32_t k = 0; k < s.num_infinite_lights; ++k) {
          uint32_t li = static_cast<uint32_t>(s.infinite_lights[k]);
          Rgb Le = environment_radiance(s, s.lights[li], ray.d);
          if (depth == 0 || specular_bounce || !settings.nee) {
            L += beta * Le;
          } else {
            Float light_pdf = s.light_select.discrete_pmf(li) * environment_pdf(s, li, ray.d);
            L += beta * Le * power_heuristic(prev_bsdf_pdf, light_pdf);
          }
        }
      }
      break;
    }
    ++c.vertices;
    SurfaceHit h = make_surface_hit(s, hit.triangle, hit.b1, hit.b2);
    Vec3 wo = -ray.d;
    const TriangleInfo& info = s.triangles[hit.triangle];

    if constexpr ((Spec & kSpecAreaLights) != 0) {
      if (info.light >= 0) {
        const Light& l = s.lights[info.light];
        Float cos_l = glm::dot(h.ng, wo);
        if (l.two_sided || cos_l > 0.f) {
          if (depth == 0 || specular_bounce || !settings.nee) {
            L += beta * l.L;
          } else {
            Float light_pdf = s.light_select.discrete_pmf(static_cast<uint32_t>(info.light)) *
                              area_light_pdf(l.area, glm::length(h.p - prev_p), cos_l);
            L += beta * l.L * power_heuristic(prev_bsdf_pdf, light_pdf);
          }
        }
      }
    }

    BsdfParams bsdf;
    if (!resolve_bsdf<Spec>(s, info.material, h, wo, &bsdf)) {
      // Interface: continue through without counting a bounce (pbrt's SkipIntersection).
      ++c.interface_skips;
      if (++interface_skips > 256) break;
      ray.o = offset_ray_origin(h, ray.d);
      continue;
    }
    if (depth++ == settings.max_depth) break;

    // Anisotropic BSDFs need pbrt's orientation (x along dp/du); any frame
    // around the normal serves the isotropic ones.
    Frame frame = (Spec & kSpecNonDiffuse) && bsdf.alpha_x != bsdf.alpha_y
                      ? Frame::from_tangent(h.ns, surface_dpdu(s, hit.triangle))
                      : Frame::from_z(h.ns);
    Vec3 wo_l = frame.to_local(wo);
    if (wo_l.z == 0.f) break;
    uint32_t lobes = (Spec & kSpecNonDiffuse) ? bsdf_lobes(bsdf) : (kLobeReflection | kLobeDiffuse);

    // Next-event estimation at non-specular vertices (pbrt-v4's SampleLd).
    if (settings.nee && lobes_have_non_specular(lobes) && s.num_lights > 0) {
      Float u_select = rng.uniform();
      Vec2 u_light = rng.uniform2();
      Float pmf = 0.f;
      uint32_t li = s.light_select.sample_discrete(u_select, &pmf);
      LightSample ls;
      if (pmf > 0.f && sample_light(s, li, h.p, u_light, &ls)) {
        Vec3 wi_l = frame.to_local(ls.wi);
        Rgb f = eval_f<Spec>(bsdf, wo_l, wi_l) * abs_cos_theta(wi_l);
        if (!is_black(f)) {
          Vec3 o = offset_ray_origin(h, ls.wi);
          Float tmax = kInfinity;
          if (!ls.infinite) tmax = glm::length(ls.p_light - o) * 0.9999f;
          ++c.shadow_rays;
          Float light_pdf = pmf * ls.pdf;
          if (light_pdf > 0.f && !tracer.occluded(o, ls.wi, tmax)) {
            Float w = 1.f;
            if (!ls.delta) w = power_heuristic(light_pdf, eval_pdf<Spec>(bsdf, wo_l, wi_l));
            L += beta * f * ls.L * (w / light_pdf);
          }
        }
      }
    }

    Float uc = rng.uniform();
    Vec2 u = rng.uniform2();
    BsdfSample bs;
    if (!sample_f<Spec>(bsdf, wo_l, uc, u, &bs) || !(bs.pdf > 0.f)) break;
    beta *= bs.f * (abs_cos_theta(bs.wi) / bs.pdf);
    prev_bsdf_pdf = bs.pdf;
    specular_bounce = (bs.lobe & kLobeSpecular) != 0;
    if (bs.lobe & kLobeTransmission) eta_scale *= sqr(bs.eta);
    Vec3 wi = frame.to_world(bs.wi);
    ray.o = offset_ray_origin(h, wi);
    ray.d = wi;
    prev_p = h.p;

    // Russian roulette (pbrt-v4): after the second bounce, on throughput
    // corrected for radiance scaling at refractive boundaries.
    Rgb rr_beta = beta * eta_scale;
    Float m = max_component(rr_beta);
    if (m < 1.f && depth > 1) {
      Float q = glm::max(0.f, 1.f - m);
      if (rng.uniform() < q) break;
      beta /= 1.f - q;
    }
    if (is_black(beta)) break;
  }
  return L;
}

}  // namespace tessera
