// render_tile's body for any ray-query type, instantiated by each CPU
// backend (render/embree_backend.cpp, render/bvh_backend.cpp) for its tracer.
#pragma once

#include <utility>
#include <vector>

#include "integrator/light_paths.h"
#include "render/pixel_sample.h"
#include "render/render_tile.h"

namespace tessera {

// Light paths draw independent numbers of their own (seed, pixel, sample).
SamplerSetup light_path_sampler(const TileSettings& settings);
// Merges the splats from `first` on that reach the same pixel (one per path and pixel).
void merge_splats_by_pixel(std::vector<Splat>& splats, size_t first);

// Media scenes and the neural guide run the full surface integrator (see
// kSpecMedia, kSpecNeural), except the neural guide in scenes of Lambertian
// surfaces and area lights alone (no textures, no environment), the common
// case, which gets an instantiation of its own (the full one's generic BSDF
// code is a few per cent of such a render): every index with those bits
// maps to one of five instantiations (kSpecNeural without kSpecGuiding
// means nothing: dropped).
constexpr uint32_t kSpecNeuralLambertian = kSpecNeural | kSpecGuiding | kSpecAreaLights;
constexpr uint32_t instantiated_spec(uint32_t s) {
  if ((s & kSpecNeural) && (s & kSpecGuiding)) {
    if (lambertian_area_lights_only(s)) return kSpecNeuralLambertian;
    return kSpecNeural | kSpecSurfaceAll | (s & kSpecMedia);
  }
  s &= ~kSpecNeural;
  if (!(s & kSpecMedia)) return s;
  return kSpecMedia | (kSpecSurfaceAll & ~kSpecGuiding) | (s & kSpecGuiding);
}

// Adds samples [sample_begin, sample_end) of every pixel of the job, in
// sample order, and with light-traced caustics one light path per sample
// whose splats are appended to *splats. ReuseFirstSite: with the neural
// guide, a pixel's samples share the network's site at their first vertex
// where they hit the same spot (NeuralFirstSite, guidecache/path_guide.h;
// the same on any thread and rank: a pixel's samples of a job are traced
// in order by one thread).
template <uint32_t Spec, class Tracer, bool ReuseFirstSite = false>
TileCounters render_tile_spec(const SceneView& s, const Tracer& scene_tracer, const TileSettings& settings,
                              const TileJob& job, TilePixels pixels, std::vector<Splat>* splats) {
  TileCounters tc;
  Tracer tracer = scene_tracer;  // counting the rays it refuses in the tile's counters
  tracer.untraceable = &tc.path.untraceable_rays;
  PathSettings path = settings.path;
  NeuralFirstSite first_site;
  constexpr bool kReuse = ReuseFirstSite && (Spec & kSpecNeural) != 0;
  if constexpr (kReuse) path.neural_first = &first_site;
  const bool light_paths = path.light_traced_caustics && splats != nullptr;
  const SamplerSetup light_sampler = light_path_sampler(settings);
  auto add_splat = [&](uint64_t pixel, const Rgb& v) {
    Splat sp;
    sp.pixel = pixel;
    sp.value[0] = v.x;
    sp.value[1] = v.y;
    sp.value[2] = v.z;
    splats->push_back(sp);
  };
  for (int32_t y = job.y0; y < job.y1; ++y) {
    for (int32_t x = job.x0; x < job.x1; ++x) {
      // Tiles are in film pixels; samples belong to the image's pixel, so a
      // crop renders what the whole image has there.
      const int32_t ix = s.camera.film_x0 + x, iy = s.camera.film_y0 + y;
      const uint64_t pixel_index = static_cast<uint64_t>(iy) * static_cast<uint64_t>(s.camera.width) + ix;
      PixelAccum& acc = pixels.at(job, x, y);
      first_site.valid = false;
      for (uint32_t si = job.sample_begin; si < job.sample_end; ++si) {
        add_camera_sample<Spec>(s, tracer, settings, path, ix, iy, si, acc, tc);
        if (light_paths) {
          PixelSampler light_rng = PixelSampler::start(light_sampler, static_cast<uint32_t>(ix),
                                                       static_cast<uint32_t>(iy), pixel_index, si);
          Wavelengths light_wl;
          if (s.spectral.enabled) light_wl = sample_wavelengths(light_rng.uniform());
          const size_t first = splats->size();
          trace_caustic_light_path<Spec>(s, tracer, light_rng, path, s.spectral.enabled ? &light_wl : nullptr, tc.path,
                                         add_splat);
          merge_splats_by_pixel(*splats, first);
        }
      }
    }
  }
  return tc;
}

}  // namespace tessera
