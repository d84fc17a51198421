#include "worker/render_tile.h"

#include "kernels/light_paths.h"

#include <algorithm>
#include <array>
#include <stdexcept>
#include <utility>

namespace tessera {
namespace {

// Light paths draw independent numbers of their own (seed, pixel, sample):
// low discrepancy buys little for one splat per sample.
SamplerSetup light_path_sampler(const TileSettings& settings) {
  SamplerSetup setup;
  setup.kind = SamplerKind::Independent;
  setup.seed = mix_bits(settings.seed ^ 0x116847a7e5ull);
  return setup;
}

// A light path connects at every vertex after its specular chain and may
// reach a pixel more than once: its splats there become one, so that the
// film's second moments are per path (the variance layer needs them so).
void merge_splats_by_pixel(std::vector<Splat>& splats, size_t first) {
  if (splats.size() - first < 2) return;
  std::stable_sort(splats.begin() + static_cast<std::ptrdiff_t>(first), splats.end(),
                   [](const Splat& a, const Splat& b) { return a.pixel < b.pixel; });
  size_t out = first;
  for (size_t i = first + 1; i < splats.size(); ++i) {
    if (splats[i].pixel == splats[out].pixel) {
      for (int c = 0; c < 3; ++c) splats[out].value[c] += splats[i].value[c];
    } else {
      splats[++out] = splats[i];
    }
  }
  splats.resize(out + 1);
}

template <uint32_t Spec, class Tracer>
TileCounters render_tile_spec(const SceneView& s, const Tracer& tracer, const TileSettings& settings,
                              const TileJob& job, TilePixels pixels, std::vector<Splat>* splats) {
  TileCounters tc;
  PathSettings path = settings.path;
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
      for (uint32_t si = job.sample_begin; si < job.sample_end; ++si) {
        PixelSampler rng = PixelSampler::start(settings.sampler, static_cast<uint32_t>(ix), static_cast<uint32_t>(iy), pixel_index, si);
        const CameraSample cs = sample_camera_ray(s, ix, iy, rng);
        path.learn = settings.learn.learns(si);
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
        // Radiance at three wavelengths to linear sRGB. A single sample's RGB
        // may be negative (a spectral line outside the sRGB gamut): the mean is not.
        if (s.spectral.enabled) L = spectral_to_rgb(s.spectral, wl, L);
        L = film_pixel_value(s.camera, L) * cs.filter_weight;
        for (int c = 0; c < 3; ++c) {
          acc.sum[c] += L[c];
          acc.sum_sq[c] += static_cast<double>(L[c]) * L[c];
        }
        ++acc.n;
        ++tc.samples;
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

using TileFn = TileCounters (*)(const SceneView&, const EmbreeTracer&, const TileSettings&, const TileJob&, TilePixels,
                                std::vector<Splat>*);

// Media scenes run the full surface integrator (see kSpecMedia): every
// index with the media bit maps to one of two instantiations.
constexpr uint32_t instantiated_spec(uint32_t s) {
  if (!(s & kSpecMedia)) return s;
  return kSpecMedia | (kSpecSurfaceAll & ~kSpecGuiding) | (s & kSpecGuiding);
}

template <size_t... I>
constexpr std::array<TileFn, sizeof...(I)> make_table(std::index_sequence<I...>) {
  return {&render_tile_spec<instantiated_spec(static_cast<uint32_t>(I)), EmbreeTracer>...};
}

// One instantiation per specialisation; chosen once per tile.
constexpr auto kTileFns = make_table(std::make_index_sequence<kSpecAll + 1>{});

}  // namespace

TileCounters render_tile(const SceneView& scene, const EmbreeTracer& tracer, const TileSettings& settings,
                         const TileJob& job, TilePixels pixels, std::vector<Splat>* splats) {
  if (settings.path.light_traced_caustics && !splats)
    throw std::logic_error("render_tile: light-traced caustics need a splat list");
  return kTileFns[settings.specialisation & kSpecAll](scene, tracer, settings, job, pixels, splats);
}

TileCounters render_tile(const SceneView& scene, const BvhTracer& tracer, const TileSettings& settings,
                         const TileJob& job, TilePixels pixels, std::vector<Splat>* splats) {
  if (settings.path.light_traced_caustics && !splats)
    throw std::logic_error("render_tile: light-traced caustics need a splat list");
  // The portable backend is served by the full surface integrator, or the
  // media one for scenes with media, guided or not (what
  // RenderOptions::force_full_specialisation selects): four instantiations
  // instead of one per effects set keep the build short.
  constexpr uint32_t kSurface = kSpecSurfaceAll & ~kSpecGuiding;
  constexpr uint32_t kMedia = instantiated_spec(kSpecMedia | kSurface);
  const bool media = (settings.specialisation & kSpecMedia) != 0, guided = (settings.specialisation & kSpecGuiding) != 0;
  if (media)
    return guided ? render_tile_spec<kMedia | kSpecGuiding, BvhTracer>(scene, tracer, settings, job, pixels, splats)
                  : render_tile_spec<kMedia, BvhTracer>(scene, tracer, settings, job, pixels, splats);
  return guided ? render_tile_spec<kSurface | kSpecGuiding, BvhTracer>(scene, tracer, settings, job, pixels, splats)
                : render_tile_spec<kSurface, BvhTracer>(scene, tracer, settings, job, pixels, splats);
}

}  // namespace tessera
