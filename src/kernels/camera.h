// pbrt-v4's perspective, orthographic and spherical cameras: raster (0,0)
// is the top-left corner, camera space is x right, y up, z forward. The
// perspective fov spans screen-window units [-1, 1] (the shorter axis of
// the default window); the orthographic screen window is in camera-space
// units; the spherical camera maps the whole image to the sphere
// (equal-area square or equirectangular).
#pragma once

#include "equal_area.h"
#include "sampler.h"
#include "sampling.h"
#include "scene_view.h"

namespace tessera {

struct Ray {
  Vec3 o, d;
  Float time = 0.f;  // where in the transform interval (0 = its start, 1 = its end): moving shapes
};

// pbrt-v4's SphericalCamera: the image's uv to a camera-space direction,
// equal-area (Clarberg's octahedral square) or equirectangular (theta =
// pi v, phi = 2 pi u), with y and z swapped so that camera-space y (up) is
// the pole: the equirectangular image's top row, the equal-area square's centre.
TESSERA_HOST_DEVICE inline Vec3 spherical_camera_direction(CameraProjection p, Vec2 uv) {
  Vec3 d;
  if (p == CameraProjection::SphericalEqualArea) {
    d = equal_area_square_to_sphere(glm::clamp(uv, Vec2(0.f), Vec2(1.f)));
  } else {
    const Float theta = kPi * uv.y, phi = 2.f * kPi * uv.x;
    d = Vec3(glm::sin(theta) * glm::cos(phi), glm::sin(theta) * glm::sin(phi), glm::cos(theta));
  }
  return Vec3(d.x, d.z, d.y);
}

// u_lens: a point on the lens (used only when c.lens_radius > 0; pbrt-v4's
// thin lens: the ray passes through the point of the focal plane that the
// pinhole ray meets).
// time: Ray::time; a moving camera (motion blur) is interpolated linearly
// between its start and end placements.
TESSERA_HOST_DEVICE inline Ray generate_camera_ray(const CameraView& c, Vec2 p_film, Vec2 u_lens = Vec2(0.f),
                                                   Float time = 0.f) {
  Float sx = c.screen_min.x + (p_film.x / c.width) * (c.screen_max.x - c.screen_min.x);
  Float sy = c.screen_max.y - (p_film.y / c.height) * (c.screen_max.y - c.screen_min.y);
  Vec3 d_cam(sx * c.tan_half_fov, sy * c.tan_half_fov, 1.f);
  Vec3 o_cam(0.f);
  if (c.projection == CameraProjection::Orthographic) {
    o_cam = Vec3(sx, sy, 0.f);
    d_cam = Vec3(0.f, 0.f, 1.f);
  } else if (c.projection != CameraProjection::Perspective) {
    d_cam = spherical_camera_direction(c.projection, Vec2(p_film.x / c.width, p_film.y / c.height));
  }
  Mat3 world_from_camera_linear = c.world_from_camera_linear;
  Vec3 origin = c.origin;
  if (c.moves && time > 0.f) {
    world_from_camera_linear += time * (c.world_from_camera_linear_end - c.world_from_camera_linear);
    origin = glm::mix(origin, c.origin_end, time);
  }
  Ray r;
  r.time = time;
  r.o = origin + world_from_camera_linear * o_cam;
  if (c.lens_radius > 0.f && c.projection == CameraProjection::Orthographic) {
    // pbrt-v4's orthographic thin lens, as it is written: the ray leaves the
    // lens point around the camera's origin (not around the pixel's) for
    // the pixel's point on the focal plane.
    const Vec2 lens = c.lens_radius * sample_uniform_disk_concentric(u_lens);
    const Vec3 o_lens(lens.x, lens.y, 0.f);
    d_cam = o_cam + Vec3(0.f, 0.f, c.focal_distance) - o_lens;
    r.o = origin + world_from_camera_linear * o_lens;
  } else if (c.lens_radius > 0.f && c.projection == CameraProjection::Perspective) {
    d_cam = glm::normalize(d_cam);
    const Vec2 lens = c.lens_radius * sample_uniform_disk_concentric(u_lens);
    const Vec3 focus = d_cam * (c.focal_distance / d_cam.z);
    const Vec3 o_cam(lens.x, lens.y, 0.f);
    d_cam = focus - o_cam;
    r.o = origin + world_from_camera_linear * o_cam;
  }
  r.d = glm::normalize(world_from_camera_linear * d_cam);
  return r;
}

// A sample's radiance as the film records it (pbrt-v4's RGBFilm::AddSample):
// the sensor's values, scaled down so that none exceeds the film's
// maxcomponentvalue, then white-balanced into sRGB. Without a clamp the one
// product matrix serves (the identity with pbrt's defaults: L unchanged).
TESSERA_HOST_DEVICE inline Rgb film_pixel_value(const CameraView& c, Rgb L) {
  if (!(c.max_component_value < INFINITY)) return c.pixel_from_radiance * L;
  Rgb v = c.sensor_from_radiance * L;
  const Float m = glm::max(v.x, glm::max(v.y, v.z));
  if (m > c.max_component_value) v *= c.max_component_value / m;
  return c.pixel_from_sensor * v;
}

// Offset within the pixel drawn from the filter (filter importance sampling:
// every sample lands in its own pixel, so tiles never overlap), and the
// sample's weight: 1, or for filters with negative lobes +-integral|f|/integral f.
TESSERA_HOST_DEVICE inline Float sample_filter_axis(const Float* inverse_cdf, uint32_t n, Float u) {
  Float x = u * static_cast<Float>(n - 1);
  uint32_t i = glm::min(static_cast<uint32_t>(x), n - 2);
  Float t = x - static_cast<Float>(i);
  return (1.f - t) * inverse_cdf[i] + t * inverse_cdf[i + 1];
}

TESSERA_HOST_DEVICE inline Float filter_axis_weight(const Float* weight, uint32_t bins, Float offset, Float radius) {
  const Float x = (offset / radius + 1.f) * 0.5f * static_cast<Float>(bins);
  const uint32_t i = static_cast<uint32_t>(glm::clamp(x, 0.f, static_cast<Float>(bins - 1)));
  return weight[i];
}

struct FilterSample {
  Vec2 offset;
  Float weight;
};

TESSERA_HOST_DEVICE inline FilterSample sample_filter(const FilterView& f, Vec2 u) {
  FilterSample s;
  s.offset = Vec2(sample_filter_axis(f.inverse_cdf_x, f.n, u.x), sample_filter_axis(f.inverse_cdf_y, f.n, u.y));
  s.weight = 1.f;
  if (f.weight_x)
    s.weight = filter_axis_weight(f.weight_x, f.bins, s.offset.x, f.radius_x) *
               filter_axis_weight(f.weight_y, f.bins, s.offset.y, f.radius_y);
  return s;
}

// The camera ray of one pixel sample and its filter weight: a film position
// from the filter, then a lens position (only when there is a lens, so that
// pinhole images keep their random streams).
struct CameraSample {
  Ray ray;
  Float filter_weight;
};

TESSERA_HOST_DEVICE inline CameraSample sample_camera_ray(const SceneView& s, int32_t x, int32_t y, PixelSampler& sampler) {
  const FilterSample fs = sample_filter(s.filter, sampler.pixel2());
  const Vec2 p_film(x + 0.5f + fs.offset.x, y + 0.5f + fs.offset.y);
  const Vec2 u_lens = s.camera.lens_radius > 0.f ? sampler.uniform2() : Vec2(0.f);
  // Motion blur: a time in the shutter interval, as a fraction of the
  // transform interval (pbrt-v4's TransformTimes), drawn only where something moves.
  Float time = 0.f;
  if (s.positions_end || s.camera.moves || s.instances_move) {
    const Float t = s.camera.shutter_open + sampler.uniform() * (s.camera.shutter_close - s.camera.shutter_open);
    time = glm::clamp((t - s.camera.transform_start_time) /
                          (s.camera.transform_end_time - s.camera.transform_start_time), 0.f, 1.f);
  }
  return CameraSample{generate_camera_ray(s.camera, p_film, u_lens, time), fs.weight};
}

}  // namespace tessera
