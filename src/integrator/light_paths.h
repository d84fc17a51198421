// Light-traced caustics: the paths a camera path cannot find.
//
// A path from a small light through a chain of specular surfaces (glass,
// mirrors) to a diffuse surface or a medium that the camera sees (L S+ x E)
// is found by the path tracer only when a direction sampled at x happens to
// run through the chain and hit the light: for a small light almost never,
// for a point or spot light never. Traced from the light instead, the chain
// is deterministic and x is connected to the pinhole directly: pbrt-v4's
// bdpt strategy t = 1 for exactly these paths.
//
// The two estimators split the path space between them, so no MIS is needed.
// The light tracer takes every path that leaves an area, point or spot light
// through at least one surface with only delta lobes, and whose first vertex
// seen from the camera scatters non-specularly (a non-delta lobe, or a
// medium): it walks from the light through that chain to the first vertex
// that can scatter non-specularly, y, and on from there as a random walk,
// connecting y and each later such vertex to the camera. The path tracer
// skips the emission of exactly those paths (PathSettings::
// light_traced_caustics): an emitter hit right after a delta-only vertex on a
// path whose first vertex sampled a non-delta lobe. So light focused by glass
// into a medium or onto a wall is traced from the light both where the camera
// sees it directly and where it is seen after further scattering (a fog lit
// by a caustic).
//
// One light path is traced per camera sample, from the sample's own random
// numbers; its connection is spread over the pixels whose filter covers it
// (with the density the camera samples are drawn from, so both estimate the
// same filtered image) and each pixel's sum is divided by the number of light
// paths traced for the whole image (Film::light_paths).
//
// Only a pinhole perspective camera and static scenes: the caller enables it
// (scene/light_paths.h says when). In spectral transport the light path
// carries its own three wavelengths, as a camera path does.
#pragma once

#include "kernels/bsdf_spec.h"
#include "kernels/light_sampling.h"
#include "kernels/material_eval.h"
#include "integrator/path_state.h"
#include "kernels/volume_transport.h"

namespace tessera {

// A point as the pinhole sees it: its raster position, the unit direction
// from the point to the camera, and the factor that turns radiance leaving
// the point towards the camera into the filtered pixel value per unit area
// (volume) of the point: J(w) / d^2, J = d(raster area) / d(solid angle).
struct FilmProjection {
  Vec2 raster;
  Vec3 to_camera;
  Float dist = 0.f;
  Float importance = 0.f;
};

TESSERA_HOST_DEVICE inline bool project_to_film(const CameraView& c, const Vec3& p, FilmProjection* out) {
  const Vec3 v_world = c.origin - p;
  const Float dist2 = glm::dot(v_world, v_world);
  if (!(dist2 > 0.f)) return false;
  const Mat3& m = c.world_from_camera_linear;
  const Float det = glm::determinant(m);
  if (!(glm::abs(det) > 0.f)) return false;
  const Vec3 q = glm::inverse(m) * (p - c.origin);  // camera space
  if (!(q.z > 0.f)) return false;
  const Vec3 d_cam(q.x / q.z, q.y / q.z, 1.f);  // generate_camera_ray's unnormalised direction
  const Float span_x = c.screen_max.x - c.screen_min.x, span_y = c.screen_max.y - c.screen_min.y;
  const Float sx = d_cam.x / c.tan_half_fov, sy = d_cam.y / c.tan_half_fov;
  out->raster = Vec2((sx - c.screen_min.x) / span_x * c.width, (c.screen_max.y - sy) / span_y * c.height);
  // Plane area at z = 1 per unit of raster area, and the solid angle of a
  // patch of that plane seen through the (possibly scaled) camera transform.
  const Float plane_per_raster = (span_x * c.tan_half_fov / c.width) * (span_y * c.tan_half_fov / c.height);
  const Float len = glm::length(m * d_cam);
  out->dist = glm::sqrt(dist2);
  out->to_camera = v_world / out->dist;
  out->importance = len * len * len / (glm::abs(det) * plane_per_raster) / dist2;
  return out->importance > 0.f && out->importance < kInfinity;
}

// Density of the filter's offset distribution along one axis at `offset`:
// the piecewise-constant density of sample_filter_axis's piecewise-linear
// inverse cdf (the camera samples' own distribution, so that splats and
// camera samples weight the image alike).
TESSERA_HOST_DEVICE inline Float filter_axis_density(const Float* inverse_cdf, uint32_t n, Float offset) {
  if (n < 2 || !(offset >= inverse_cdf[0]) || !(offset < inverse_cdf[n - 1])) return 0.f;
  uint32_t lo = 0, hi = n - 1;  // inverse_cdf[lo] <= offset < inverse_cdf[hi]
  while (hi - lo > 1) {
    const uint32_t mid = (lo + hi) / 2;
    if (inverse_cdf[mid] <= offset) lo = mid;
    else hi = mid;
  }
  const Float width = inverse_cdf[hi] - inverse_cdf[lo];
  return width > 0.f ? 1.f / (static_cast<Float>(n - 1) * width) : 0.f;
}

// Spreads value (one light path's contribution, before the division by the
// image's light-path count) over the film's pixels whose filter reaches
// `raster` (image raster coordinates), calling sink(film pixel index, rgb).
template <class Sink>
TESSERA_HOST_DEVICE inline uint32_t splat_filtered(const SceneView& s, Vec2 raster, const Rgb& value, Sink&& sink) {
  const FilterView& f = s.filter;
  // Points beyond the filter's reach of the image (also: before any int cast).
  if (!(raster.x > -f.radius_x && raster.x < s.camera.width + f.radius_x && raster.y > -f.radius_y &&
        raster.y < s.camera.height + f.radius_y))
    return 0;
  const int32_t x0 = static_cast<int32_t>(glm::floor(raster.x - 0.5f - f.radius_x));
  const int32_t x1 = static_cast<int32_t>(glm::floor(raster.x - 0.5f + f.radius_x));
  const int32_t y0 = static_cast<int32_t>(glm::floor(raster.y - 0.5f - f.radius_y));
  const int32_t y1 = static_cast<int32_t>(glm::floor(raster.y - 0.5f + f.radius_y));
  uint32_t splats = 0;
  const CameraView& c = s.camera;
  for (int32_t y = glm::max(y0, c.film_y0); y <= glm::min(y1, c.film_y0 + c.film_height - 1); ++y) {
    const Float dy = raster.y - (y + 0.5f);
    const Float wy = filter_axis_density(f.inverse_cdf_y, f.n, dy);
    if (wy == 0.f) continue;
    for (int32_t x = glm::max(x0, c.film_x0); x <= glm::min(x1, c.film_x0 + c.film_width - 1); ++x) {
      const Float dx = raster.x - (x + 0.5f);
      Float w = wy * filter_axis_density(f.inverse_cdf_x, f.n, dx);
      if (w == 0.f) continue;
      if (f.weight_x)
        w *= filter_axis_weight(f.weight_x, f.bins, dx, f.radius_x) * filter_axis_weight(f.weight_y, f.bins, dy, f.radius_y);
      sink(static_cast<uint64_t>(y - c.film_y0) * static_cast<uint64_t>(c.film_width) + static_cast<uint64_t>(x - c.film_x0),
           value * w);
      ++splats;
    }
  }
  return splats;
}

// pbrt-v4's correction for shading normals in importance transport: the
// adjoint BSDF of a vertex with shading normal ns and geometric normal ng.
TESSERA_HOST_DEVICE inline Float shading_normal_correction(const Vec3& wo, const Vec3& wi, const Vec3& ns,
                                                           const Vec3& ng) {
  const Float denom = glm::abs(glm::dot(wo, ng)) * glm::abs(glm::dot(wi, ns));
  return denom > 0.f ? glm::abs(glm::dot(wo, ns)) * glm::abs(glm::dot(wi, ng)) / denom : 0.f;
}

// Adds a scattering point's light towards the camera (contribution: the
// light path's weight times the BSDF or phase value and the cosine there) to
// the pixels that see it. The segment is traced from the camera, in the
// camera's medium and across interfaces as a camera ray would be, so that it
// sees the media the path tracer's first segment sees even where a surface's
// MediumInterface contradicts them.
template <bool kMedia, class Tracer, class Sink>
TESSERA_HOST_DEVICE inline void connect_to_camera(const SceneView& s, const Tracer& tracer, const FilmProjection& fp,
                                                  const Rgb& contribution, const Wavelengths* wl, PathCounters& c,
                                                  Sink&& sink) {
  if (is_black(contribution)) return;
  // Stops short of the point by a relative 1e-4 so as not to hit its own surface.
  const Rgb tr = light_visibility<kMedia>(s, tracer, s.camera.origin, -fp.to_camera, fp.dist * 0.9999f,
                                          kMedia ? s.camera_medium : -1, 0.f, c, wl);
  if (is_black(tr)) return;
  Rgb radiance = contribution * tr * fp.importance;
  if (wl) radiance = spectral_to_rgb(s.spectral, *wl, radiance);
  // The film's linear response only: a splat is a sum over the image's light
  // paths, not one sample, so the per-sample maxcomponentvalue clamp does
  // not apply to it.
  const Rgb value = s.camera.pixel_from_radiance * radiance;
  if (!is_finite(value)) return;
  c.light_splats += splat_filtered(s, fp.raster, value, sink);
}

// Where a light path for the caustic strategy starts: a point and direction
// on light l (selected with probability pmf) from (u_pos, u_dir), its weight
// *beta and the medium it leaves into. False: a light the path tracer
// delivers alone (distant, infinite) or no direction.
template <uint32_t Spec>
TESSERA_HOST_DEVICE inline bool start_light_path(const SceneView& s, const Light& l, Float pmf, Vec2 u_pos, Vec2 u_dir,
                                                 Wavelengths* wl, Ray* ray_out, Rgb* beta_out, int32_t* medium_out) {
  constexpr bool kMedia = (Spec & kSpecMedia) != 0;
  Ray& ray = *ray_out;
  Rgb& beta = *beta_out;
  int32_t& medium = *medium_out;
  switch (l.type) {
    case LightType::Area: {
      const Vec3 b = sample_uniform_triangle(u_pos);
      const SurfaceHit h = make_surface_hit(s, l.triangle, b.y, b.z);
      Vec3 n = h.ng;  // the emitting side
      Float sides = 1.f;
      Vec2 u = u_dir;
      if (l.two_sided) {
        sides = 2.f;
        if (u.x < 0.5f) {
          n = -n;
          u.x *= 2.f;
        } else {
          u.x = (u.x - 0.5f) * 2.f;
        }
        u.x = glm::min(u.x, 0x1.fffffep-1f);
      }
      const Vec3 local = sample_cosine_hemisphere(u);
      if (!(local.z > 0.f)) return false;
      ray.d = Frame::from_z(n).to_world(local);
      ray.o = offset_ray_origin(h, ray.d);
      // Le cos / (pmf * (1 / area) * (cos / pi) / sides)
      beta = light_emission(s, wl, l, area_light_radiance(s, l, h.uv)) * (kPi * l.area * sides / pmf);
      if constexpr (kMedia) {
        // The shape's medium on the side the light leaves into.
        if (s.triangle_media) {
          const MediumInterface mi = s.triangle_media[l.triangle];
          medium = is_transition(mi) ? medium_towards(mi, h.ng, ray.d) : mi.outside;
        }
      }
      break;
    }
    case LightType::Point:
    case LightType::Goniometric:
    case LightType::Projection:
      ray.o = l.position;
      ray.d = sample_uniform_sphere(u_dir);
      beta = light_emission(s, wl, l, point_like_intensity(s, l, ray.d)) * (4.f * kPi / pmf);
      break;
    case LightType::Spot: {
      // Uniform in the cone of cos_falloff_end, weighted by the falloff.
      const Float cos_end = glm::clamp(l.cos_falloff_end, -1.f, 1.f);
      const Float cos_t = 1.f - u_dir.x * (1.f - cos_end);
      const Float sin_t = glm::sqrt(glm::max(0.f, 1.f - cos_t * cos_t));
      const Float phi = 2.f * kPi * u_dir.y;
      ray.o = l.position;
      ray.d = Frame::from_z(l.direction).to_world(Vec3(sin_t * glm::cos(phi), sin_t * glm::sin(phi), cos_t));
      beta = light_emission(s, wl, l, l.L) * (spot_falloff(l, cos_t) * 2.f * kPi * (1.f - cos_end) / pmf);
      break;
    }
    default:
      return false;  // distant and infinite lights: the path tracer's
  }
  return true;
}

// The walk's bookkeeping: first the chain of delta-only surfaces (at least
// one), then y, the first vertex that scatters non-specularly, then on as a
// random walk; y and every later vertex that can scatter non-specularly is
// connected to the camera, as long as the path's vertex count stays within
// max_depth.
struct LightWalk {
  int32_t vertices = 0;      // scattering vertices so far (pbrt-v4's depth)
  bool past_chain = false;   // y reached
  Float beta_at_y = 0.f;     // roulette after y compares with this
  int32_t interface_skips = 0;
  // A vertex that can scatter non-specularly: y if none came before (one
  // reached straight from the light is next-event estimation's), counted
  // against max_depth. False ends the walk.
  TESSERA_HOST_DEVICE bool reach_scattering_vertex(const Rgb& beta, int32_t max_depth) {
    if (!past_chain) {
      if (vertices == 0) return false;
      beta_at_y = max_component(beta);
      past_chain = true;
    }
    return ++vertices <= max_depth;
  }
  // Continues the walk from a scattering vertex past y; false ends it.
  TESSERA_HOST_DEVICE bool roulette(Rgb& beta, PixelSampler& rng) const {
    if (vertices < 3) return true;
    const Float survive = glm::min(1.f, max_component(beta) / beta_at_y);
    if (survive >= 1.f) return true;
    if (!(survive > 0.f) || rng.uniform() >= survive) return false;
    beta /= survive;
    return true;
  }
};

// A surface vertex that can scatter non-specularly, connected to the camera:
// the path tracer's f(to camera, to light) |cos to light| in area measure.
template <uint32_t Spec, class Tracer, class Sink>
TESSERA_HOST_DEVICE inline void connect_surface_to_camera(const SceneView& s, const Tracer& tracer, const SurfaceHit& h,
                                                          const BsdfParams& bsdf, const Frame& frame, const Vec3& wo,
                                                          const Rgb& beta, Wavelengths* wl, PathCounters& c, Sink&& sink) {
  FilmProjection fp;
  const Float cos_ng_l = glm::abs(glm::dot(h.ng, wo));
  if (cos_ng_l > 0.f && project_to_film(s.camera, h.p, &fp)) {
    const Rgb f = eval_f<Spec>(bsdf, frame.to_local(fp.to_camera), frame.to_local(wo));
    const Float cosines = glm::abs(glm::dot(h.ns, wo)) * glm::abs(glm::dot(h.ng, fp.to_camera)) / cos_ng_l;
    connect_to_camera<(Spec & kSpecMedia) != 0>(s, tracer, fp, beta * f * cosines, wl, c, sink);
  }
}

// One light path for the caustic strategy (wl: its wavelengths in spectral
// transport, else null).
template <uint32_t Spec, class Tracer, class Sink>
TESSERA_HOST_DEVICE void trace_caustic_light_path(const SceneView& s, const Tracer& tracer, PixelSampler& rng,
                                                  const PathSettings& settings, Wavelengths* wl, PathCounters& c,
                                                  Sink&& sink) {
  constexpr bool kMedia = (Spec & kSpecMedia) != 0;
  if (s.num_lights == 0) return;
  ++c.light_paths;
  const Float u_select = rng.uniform();
  const Vec2 u_pos = rng.uniform2();
  const Vec2 u_dir = rng.uniform2();
  Float pmf = 0.f;
  const uint32_t li = s.light_select.sample_discrete(u_select, &pmf);
  if (!(pmf > 0.f)) return;
  const Light& l = s.lights[li];
  Ray ray;
  Rgb beta(0.f);
  int32_t medium = kMedia ? l.medium : -1;  // point and spot lights: where they were defined
  HeroChannels heroes;  // the channel media sample distances with (medium.h)
  if (!start_light_path<Spec>(s, l, pmf, u_pos, u_dir, wl, &ray, &beta, &medium)) return;
  if (is_black(beta)) return;

  LightWalk walk;
  for (;;) {
    TraceHit hit;
    ++c.rays;
    const bool found = tracer.intersect(ray.o, ray.d, kInfinity, &hit, 0.f);
    if constexpr (kMedia) {
      if (medium >= 0) {
        const Medium m = medium_at(s, medium, wl);
        const Float t_max = found ? hit.t : kInfinity;
        if (medium_absorbs_only(m)) {
          beta *= medium_transmittance(s, m, ray.o, ray.d, t_max, wl);
        } else {
          const Float u_channel = rng.uniform();
          const Float u_dist = rng.uniform();
          const MediumSegment seg = sample_medium(s, m, ray.o, ray.d, t_max, u_channel, u_dist, wl, heroes);
          beta *= seg.weight;
          if (seg.scattered) {
            if (!walk.reach_scattering_vertex(beta, settings.max_depth) || is_black(beta)) return;
            const Vec3 p = ray.o + seg.t * ray.d;
            FilmProjection fp;
            if (project_to_film(s.camera, p, &fp)) {
              const Float phase = henyey_greenstein(glm::dot(-ray.d, fp.to_camera), m.g);
              connect_to_camera<kMedia>(s, tracer, fp, beta * phase, wl, c, sink);
            }
            if (walk.vertices == settings.max_depth || !walk.roulette(beta, rng)) return;
            Float phase_pdf = 0.f;
            const Vec3 wi = sample_henyey_greenstein(-ray.d, m.g, rng.uniform2(), &phase_pdf);
            if (!(phase_pdf > 0.f)) return;  // exact sampling: the weight is 1
            ray.o = p;
            ray.d = wi;
            continue;
          }
        }
        if (is_black(beta)) return;
      }
    }
    if (!found) return;
    const RayPoint from_ray{ray.o, ray.d, hit.t};
    SurfaceHit h = make_surface_hit(s, hit, 0.f, &from_ray);
    const Vec3 wo = -ray.d;  // towards the light
    BsdfParams bsdf;
    const int32_t single_before = wl ? wl->single : -1;
    if (!resolve_bsdf<Spec>(s, s.triangles[hit.triangle].material, h, wo, &bsdf, wl)) {
      if (++walk.interface_skips > 256) return;
      if constexpr (kMedia) medium = medium_after(s, hit.triangle, h.ng, ray.d, medium);
      ray.o = offset_ray_origin(h, ray.d);
      continue;
    }
    if (wl && wl->single != single_before) {  // as trace_path
      beta *= dispersion_mask(wl->single);
      if constexpr (kMedia) keep_only_channel(heroes, wl->single);
    }
    const Frame frame = shading_frame<Spec>(s, bsdf, h);
    if (lobes_have_non_specular(lobes_of<Spec>(bsdf))) {
      if (!walk.reach_scattering_vertex(beta, settings.max_depth)) return;
      connect_surface_to_camera<Spec>(s, tracer, h, bsdf, frame, wo, beta, wl, c, sink);
      if (walk.vertices == settings.max_depth || !walk.roulette(beta, rng)) return;
    } else {
      // Only delta lobes: a chain vertex, or one on the walk after y; a
      // camera connection needs one more vertex.
      if (++walk.vertices + 1 > settings.max_depth) return;
    }
    const Vec3 wo_l = frame.to_local(wo);
    BsdfSample bs;
    if (!sample_f<Spec>(bsdf, wo_l, rng.uniform(), rng.uniform2(), &bs) || !(bs.pdf > 0.f)) return;
    Vec3 wi = frame.to_world(bs.wi);
    // Importance transport: no 1/eta^2 at refraction (the BSDFs scale for
    // radiance), and pbrt-v4's shading-normal correction.
    Float w = abs_cos_theta(bs.wi) / bs.pdf * shading_normal_correction(wo, wi, h.ns, h.ng);
    if (bs.lobe & kLobeTransmission) w *= sqr(bs.eta);
    beta *= bs.f * w;
    if (is_black(beta) || !is_finite(beta)) return;
    // The weight above is the sampled direction's; only the ray is kept on its lobe's side (as trace_path).
    if (keeps_lobe_side(bsdf, bs.lobe)) wi = keep_on_lobe_side(wi, wo, h.ng, (bs.lobe & kLobeTransmission) != 0);
    if constexpr (kMedia) medium = medium_after(s, hit.triangle, h.ng, wi, medium);
    ray.o = offset_ray_origin(h, wi);
    ray.d = wi;
  }
}

}  // namespace tessera
