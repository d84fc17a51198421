// Sampling incident radiance from one light (next-event estimation) and the
// matching solid-angle pdfs for MIS when a BSDF-sampled ray finds a light.
#pragma once

#include "equal_area.h"
#include "sampling.h"
#include "spherical_triangle.h"
#include "surface.h"
#include "texture_eval.h"

namespace tessera {

struct LightSample {
  Rgb L{0.f};        // radiance (or intensity / r^2 for point-like lights) arriving at the reference point
  Vec3 wi{0.f};      // unit direction from the reference point to the light
  Vec3 p_light{0.f}; // point on the light (finite lights) for the shadow ray
  Float pdf = 0.f;   // solid-angle pdf of wi (1 for delta lights)
  bool delta = false;
  bool infinite = false;  // shadow ray runs to infinity
};

// Solid-angle density, seen from o, of sampling the portal's rectangle
// uniformly by area, for the unit direction d: where the ray (o, d) crosses
// the rectangle towards its front (dot(d, n) > 0), dist^2 / (area cos); 0
// where it misses it.
TESSERA_HOST_DEVICE inline Float portal_pdf(const Light& l, const Vec3& o, const Vec3& d) {
  const Float cos_n = glm::dot(d, l.portal_n);
  if (!(cos_n > 0.f)) return 0.f;
  const Float t = glm::dot(l.portal_p0 - o, l.portal_n) / cos_n;
  if (!(t > 0.f) || !(t < kInfinity)) return 0.f;
  const Vec3 q = o + t * d - l.portal_p0;
  const Float a = glm::dot(q, l.portal_s) / glm::dot(l.portal_s, l.portal_s);
  const Float b = glm::dot(q, l.portal_t) / glm::dot(l.portal_t, l.portal_t);
  if (!(a >= 0.f && a <= 1.f && b >= 0.f && b <= 1.f)) return 0.f;
  const Float pdf = t * t / (l.portal_area * cos_n);
  return pdf < kInfinity ? pdf : 0.f;
}

// The sky's radiance along dir (its image, or L), wherever it is seen from.
TESSERA_HOST_DEVICE inline Rgb environment_radiance(const SceneView& s, const Light& l, const Vec3& dir_world) {
  if (l.image < 0) return l.L;
  Vec3 wl = glm::normalize(l.light_from_world * dir_world);
  return l.L * image_lookup_nearest(s.images[l.image], equal_area_sphere_to_square(wl));
}

// What a ray from o along dir receives from an infinite light: with a
// portal, only through its rectangle (pbrt-v4's PortalImageInfiniteLight::Le).
TESSERA_HOST_DEVICE inline Rgb environment_radiance(const SceneView& s, const Light& l, const Vec3& o, const Vec3& dir) {
  if (l.portal_area > 0.f && !(portal_pdf(l, o, dir) > 0.f)) return Rgb(0.f);
  return environment_radiance(s, l, dir);
}

// What an area light emits at surface coordinates uv: L, times its image
// where it has one (pbrt-v4's DiffuseAreaLight::L: the image at (u, 1 - v),
// bilinear, clamped at the edges).
TESSERA_HOST_DEVICE inline Rgb area_light_radiance(const SceneView& s, const Light& l, Vec2 uv) {
  if (l.image < 0) return l.L;
  return l.L * image_lookup(s.images[l.image], uv, ImageWrap::Clamp);
}

// Solid-angle pdf of sampling a point on an area light (triangle of area
// `area`) at distance dist, seen under cos_l = dot(n_light, -w).
TESSERA_HOST_DEVICE inline Float area_light_pdf(Float area, Float dist, Float cos_l) {
  Float c = fabsf(cos_l);
  if (!(area > 0.f) || !(c > 0.f)) return 0.f;
  return dist * dist / (c * area);
}

// An area light's triangle, in the positions light samples use (the start of
// the transform interval).
struct LightTriangle {
  Vec3 v0, v1, v2;
};
TESSERA_HOST_DEVICE inline LightTriangle light_triangle(const SceneView& s, uint32_t tri) {
  const uint32_t* idx = s.indices + 3 * static_cast<size_t>(tri);
  return {s.positions[idx[0]], s.positions[idx[1]], s.positions[idx[2]]};
}

// The solid-angle pdf with which sample_light draws point p_light of area
// light l from ref_p (with the same in_medium): uniform in solid angle from
// points in media where the triangle looks large enough
// (spherical_triangle.h), else by area. For the MIS weights of directions
// that found the light.
TESSERA_HOST_DEVICE inline Float area_light_pdf_from(const SceneView& s, const Light& l, const Vec3& ref_p,
                                                     const Vec3& p_light, Float cos_l, bool in_medium) {
  if (!(fabsf(cos_l) > 0.f)) return 0.f;
  if (in_medium) {
    const LightTriangle t = light_triangle(s, l.triangle);
    const Float omega = triangle_solid_angle(ref_p, t.v0, t.v1, t.v2);
    if (samples_by_solid_angle(omega)) return 1.f / omega;
  }
  return area_light_pdf(l.area, glm::length(p_light - ref_p), cos_l);
}

// o: where the ray that escaped started (a portal's density depends on it).
TESSERA_HOST_DEVICE inline Float environment_pdf(const SceneView& s, uint32_t light_index, const Vec3& o,
                                                 const Vec3& dir_world) {
  const Light& l = s.lights[light_index];
  Float sky = kUniformSpherePdf;
  if (l.image >= 0) {
    const Vec3 wl = glm::normalize(l.light_from_world * dir_world);
    sky = s.env_distributions[light_index].pdf(equal_area_sphere_to_square(wl)) * kInv4Pi;
  }
  if (!(l.portal_area > 0.f)) return sky;
  // A portal: its rectangle by area, mixed half and half for an image with
  // the image's own distribution where that passes through the rectangle.
  const Float area = portal_pdf(l, o, dir_world);
  if (l.image < 0) return area;
  return area > 0.f ? 0.5f * (area + sky) : 0.f;
}

// Spot falloff, pbrt-v4: smoothstep between the cone's outer and inner cosines.
TESSERA_HOST_DEVICE inline Float spot_falloff(const Light& l, Float cos_theta) {
  Float e = l.cos_falloff_end, st = l.cos_falloff_start;
  if (st <= e) return cos_theta >= e ? 1.f : 0.f;
  Float t = glm::clamp((cos_theta - e) / (st - e), 0.f, 1.f);
  return t * t * (3.f - 2.f * t);
}

// A goniometric light's intensity towards world direction w (from the
// light): I times its image at w in the light's frame (pbrt-v4: nearest texel).
TESSERA_HOST_DEVICE inline Rgb goniometric_intensity(const SceneView& s, const Light& l, const Vec3& w) {
  if (l.image < 0) return l.L;
  const Vec3 wl = l.light_from_world * w;
  const Float len = glm::length(wl);
  if (!(len > 0.f)) return Rgb(0.f);
  return l.L * image_lookup_nearest(s.images[l.image], equal_area_sphere_to_square(wl / len));
}

// A projection light's intensity towards world direction w: L times the
// slide's nearest texel where w passes through the screen window (pbrt-v4's
// ProjectionLight::I; nothing behind the light or outside the window).
TESSERA_HOST_DEVICE inline Rgb projection_intensity(const SceneView& s, const Light& l, const Vec3& w) {
  const Vec3 wl = l.light_from_world * w;
  const Float len = glm::length(wl);
  if (!(len > 0.f) || !(wl.z / len >= 1e-3f)) return Rgb(0.f);  // pbrt-v4's hither
  const Vec2 ps(wl.x / (wl.z * l.tan_half_fov), wl.y / (wl.z * l.tan_half_fov));
  if (!(ps.x >= -l.screen_max.x && ps.x <= l.screen_max.x && ps.y >= -l.screen_max.y && ps.y <= l.screen_max.y))
    return Rgb(0.f);
  const Vec2 uv = (ps + l.screen_max) / (2.f * l.screen_max);
  return l.L * image_lookup_nearest(s.images[l.image], uv);
}

// What a point-like light sends towards world direction w (unit, from the light).
TESSERA_HOST_DEVICE inline Rgb point_like_intensity(const SceneView& s, const Light& l, const Vec3& w) {
  switch (l.type) {
    case LightType::Goniometric: return goniometric_intensity(s, l, w);
    case LightType::Projection: return projection_intensity(s, l, w);
    case LightType::Spot: return l.L * spot_falloff(l, glm::dot(w, l.direction));
    default: return l.L;
  }
}

// in_medium: ref_p is a scattering point in a medium (area lights are then
// sampled by solid angle where they look large: area_light_pdf_from).
TESSERA_HOST_DEVICE TESSERA_INLINE bool sample_light(const SceneView& s, uint32_t light_index, const Vec3& ref_p, Vec2 u,
                                             LightSample* out, bool in_medium = false) {
  const Light& l = s.lights[light_index];
  LightSample ls;
  switch (l.type) {
    case LightType::Area: {
      Vec3 b = sample_uniform_triangle(u);
      Float omega = 0.f;
      if (in_medium) {
        const LightTriangle t = light_triangle(s, l.triangle);
        omega = triangle_solid_angle(ref_p, t.v0, t.v1, t.v2);
        if (samples_by_solid_angle(omega)) {
          Vec3 w;
          if (!sample_spherical_triangle(ref_p, t.v0, t.v1, t.v2, u, &w)) return false;
          const Vec2 bary = triangle_barycentrics_along(ref_p, w, t.v0, t.v1, t.v2);
          b = Vec3(1.f - bary.x - bary.y, bary.x, bary.y);
        } else {
          omega = 0.f;
        }
      }
      SurfaceHit h = make_surface_hit(s, l.triangle, b.y, b.z);
      const Vec3& p = h.p;
      const Vec3& n = h.ng;  // emission side, oriented as at a hit
      Vec3 d = p - ref_p;
      Float dist2 = glm::dot(d, d);
      if (!(dist2 > 0.f)) return false;
      Float dist = glm::sqrt(dist2);
      ls.wi = d / dist;
      Float cos_l = -glm::dot(n, ls.wi);
      if (!l.two_sided && cos_l <= 0.f) return false;
      ls.pdf = omega > 0.f ? 1.f / omega : area_light_pdf(l.area, dist, cos_l);
      ls.L = area_light_radiance(s, l, h.uv);
      ls.p_light = offset_ray_origin(h, -ls.wi);
      break;
    }
    case LightType::Point:
    case LightType::Spot:
    case LightType::Goniometric:
    case LightType::Projection: {
      Vec3 d = l.position - ref_p;
      Float dist2 = glm::dot(d, d);
      if (dist2 <= 0.f) return false;
      ls.wi = d / glm::sqrt(dist2);
      ls.L = point_like_intensity(s, l, -ls.wi) / dist2;
      if (is_black(ls.L)) return false;
      ls.pdf = 1.f;
      ls.delta = true;
      ls.p_light = l.position;
      break;
    }
    case LightType::Distant: {
      ls.wi = l.direction;
      ls.L = l.L;
      ls.pdf = 1.f;
      ls.delta = true;
      ls.infinite = true;
      break;
    }
    case LightType::Infinite: {
      if (l.portal_area > 0.f) {
        // A direction through the portal: a point of its rectangle uniformly
        // by area, or for an image (half the time) the image's own
        // distribution (a sun seen through a window), kept where it passes
        // through the rectangle. The pdf is the mixture environment_pdf
        // gives escaped rays, so the MIS weights sum to 1.
        if (l.image >= 0 && u.x < 0.5f) {
          Float pdf_uv;
          const Vec2 uv = s.env_distributions[light_index].sample(Vec2(2.f * u.x, u.y), &pdf_uv);
          if (!(pdf_uv > 0.f)) return false;
          ls.wi = glm::normalize(l.world_from_light * equal_area_square_to_sphere(uv));
        } else {
          const Float ua = l.image >= 0 ? glm::min(2.f * u.x - 1.f, 0x1.fffffep-1f) : u.x;
          const Vec3 d = l.portal_p0 + ua * l.portal_s + u.y * l.portal_t - ref_p;
          const Float dist = glm::length(d);
          if (!(dist > 0.f)) return false;
          ls.wi = d / dist;
        }
        ls.pdf = environment_pdf(s, light_index, ref_p, ls.wi);  // 0 beyond the portal or off its rectangle
        ls.L = environment_radiance(s, l, ls.wi);
        ls.infinite = true;
        break;
      }
      if (l.image < 0) {
        ls.wi = sample_uniform_sphere(u);
        ls.pdf = kUniformSpherePdf;
      } else {
        Float pdf_uv;
        Vec2 uv = s.env_distributions[light_index].sample(u, &pdf_uv);
        if (pdf_uv <= 0.f) return false;
        Vec3 wl = equal_area_square_to_sphere(uv);
        ls.wi = glm::normalize(l.world_from_light * wl);
        ls.pdf = pdf_uv * kInv4Pi;
        // Radiance of the sampled texel itself (pbrt-v4 ImageLe(uv)): going
        // back through the direction could land in a neighbour at a border.
        ls.L = l.L * image_lookup_nearest(s.images[l.image], uv);
      }
      if (l.image < 0) ls.L = l.L;
      ls.infinite = true;
      break;
    }
  }
  if (!(ls.pdf > 0.f) || is_black(ls.L)) return false;
  *out = ls;
  return true;
}

}  // namespace tessera
