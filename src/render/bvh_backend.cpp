#include "render/bvh_backend.h"

#include <stdexcept>

#include "render/device_tiles.h"
#include "render/render_tile_impl.h"

namespace tessera {

TileCounters render_tile(const SceneView& scene, const BvhTracer& tracer, const TileSettings& settings,
                         const TileJob& job, TilePixels pixels, std::vector<Splat>* splats) {
  if (settings.path.light_traced_caustics && !splats)
    throw std::logic_error("render_tile: light-traced caustics need a splat list");
  return dispatch_served(settings.specialisation, [&](auto served) {
    return render_tile_spec<decltype(served)::value, BvhTracer>(scene, tracer, settings, job, pixels, splats);
  });
}

}  // namespace tessera
