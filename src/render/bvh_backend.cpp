#include "render/bvh_backend.h"

#include <stdexcept>

#include "render/device_tiles.h"
#include "render/render_tile_impl.h"

namespace tessera {

TileCounters render_tile(const SceneView& scene, const BvhTracer& tracer, const TileSettings& settings,
                         const TileJob& job, TilePixels pixels, std::vector<Splat>* splats) {
  if (settings.path.light_traced_caustics && !splats)
    throw std::logic_error("render_tile: light-traced caustics need a splat list");
  switch (served_specialisation(settings.specialisation)) {
    case kServedMedia | kSpecGuiding:
      return render_tile_spec<kServedMedia | kSpecGuiding, BvhTracer>(scene, tracer, settings, job, pixels, splats);
    case kServedMedia:
      return render_tile_spec<kServedMedia, BvhTracer>(scene, tracer, settings, job, pixels, splats);
    case kServedMedia | kSpecGuiding | kSpecNeural:
      return render_tile_spec<kServedMedia | kSpecGuiding | kSpecNeural, BvhTracer>(scene, tracer, settings, job, pixels,
                                                                                 splats);
    case kServedSurface | kSpecGuiding | kSpecNeural:
      return render_tile_spec<kServedSurface | kSpecGuiding | kSpecNeural, BvhTracer>(scene, tracer, settings, job,
                                                                                   pixels, splats);
    case kServedSurface | kSpecGuiding:
      return render_tile_spec<kServedSurface | kSpecGuiding, BvhTracer>(scene, tracer, settings, job, pixels, splats);
    default:
      return render_tile_spec<kServedSurface, BvhTracer>(scene, tracer, settings, job, pixels, splats);
  }
}

}  // namespace tessera
