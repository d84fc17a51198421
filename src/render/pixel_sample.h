// One camera sample of one pixel and how it is added to the pixel's
// accumulators: the body every backend runs, a CPU thread tile by tile or a
// GPU thread per sample. Host and device code; the random streams depend on (seed, image
// pixel, sample index) only, so a sample is the same wherever it runs.
#pragma once

#include "integrator/integrator.h"
#include "render/film.h"
#include "render/render_tile.h"

namespace tessera {

// The film value of sample `si` of image pixel (ix, iy) of the full image
// (a crop's film pixel plus its offset): radiance through the sensor, times
// the filter weight, with NaN/Inf and negative estimates rejected and
// counted. `path` is the caller's copy of settings.path (learn is set here,
// per sample); counters go to *tc.
template <uint32_t Spec, class Tracer>
TESSERA_HOST_DEVICE inline Rgb camera_sample_value(const SceneView& s, const Tracer& tracer, const TileSettings& settings,
                                                   PathSettings& path, int32_t ix, int32_t iy, uint32_t si,
                                                   TileCounters& tc) {
  const uint64_t pixel_index = static_cast<uint64_t>(iy) * static_cast<uint64_t>(s.camera.width) + ix;
  PixelSampler rng = PixelSampler::start(settings.sampler, static_cast<uint32_t>(ix), static_cast<uint32_t>(iy), pixel_index, si);
  const CameraSample cs = sample_camera_ray(s, ix, iy, rng);
  path.learn = settings.learn.learns(si);
  if constexpr ((Spec & kSpecNeural) != 0)
    if (path.neural.sink) neural_sink_start_path(path.neural.sink, pixel_index, si);
  // Spectral transport: the path's three wavelengths (spectral.h).
  Wavelengths wl;
  if (s.spectral.enabled) wl = sample_wavelengths(rng.uniform());
  Rgb L = trace_path<Spec>(s, tracer, cs.ray, rng, path, tc.path, s.spectral.enabled ? &wl : nullptr);
  if (!is_finite(L)) {
    ++tc.rejected_nonfinite;
    L = Rgb(0.f);
  } else if (L.x < 0.f || L.y < 0.f || L.z < 0.f) {
    ++tc.rejected_negative;
    L = glm::max(L, Rgb(0.f));
  }
  if (is_black(L)) ++tc.zero_radiance;
  ++tc.samples;
  // Radiance at three wavelengths to linear sRGB. A single sample's RGB
  // may be negative (a spectral line outside the sRGB gamut): the mean is not.
  if (s.spectral.enabled) L = spectral_to_rgb(s.spectral, wl, L);
  return film_pixel_value(s.camera, L) * cs.filter_weight;
}

// Adds one sample's film value to its pixel. A pixel's samples are added in
// sample order, whoever computed them: its sums do not depend on the thread
// count, the rank count or the device.
TESSERA_HOST_DEVICE inline void accumulate_sample(PixelAccum& acc, const Rgb& L) {
  for (int c = 0; c < 3; ++c) {
    acc.sum[c] += L[c];
    acc.sum_sq[c] += static_cast<double>(L[c]) * L[c];
  }
  ++acc.n;
}

template <uint32_t Spec, class Tracer>
TESSERA_HOST_DEVICE inline void add_camera_sample(const SceneView& s, const Tracer& tracer, const TileSettings& settings,
                                                  PathSettings& path, int32_t ix, int32_t iy, uint32_t si,
                                                  PixelAccum& acc, TileCounters& tc) {
  accumulate_sample(acc, camera_sample_value<Spec>(s, tracer, settings, path, ix, iy, si, tc));
}

}  // namespace tessera
