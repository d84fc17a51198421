// Picks and builds the backend a process renders with (--backend): the one
// place that knows every backend. "auto" is CUDA where this binary was
// built with it, a device is present and the scene and guide can go there,
// else Embree. Each rank of a farm picks its own.
#pragma once

#include <memory>
#include <string>

#include "render/scene_data.h"
#include "render/tile_backend.h"

namespace tessera {

// The backend's name for `requested` (auto, embree, bvh, cuda) on this
// process; *why says how auto decided (empty otherwise). With a scene (and
// whether its caustics are traced from the lights), cuda is checked against
// it too. Throws a one-line error for an unknown name and for cuda where it
// cannot render.
std::string resolve_backend(const std::string& requested, const SceneData* scene = nullptr, bool light_paths = false,
                            std::string* why = nullptr);

// Builds backend `name` (as resolve_backend gives it) over `scene`, which
// must outlive it (the device backends copy it and do not). host_threads:
// what the emulated device runs on. light_paths: the render traces
// caustics from the lights (the device backends refuse such renders).
std::unique_ptr<TileBackend> make_tile_backend(const std::string& name, const SceneData& scene,
                                               int32_t host_threads = 1, bool light_paths = false);

}  // namespace tessera
