#include "render/backends.h"

#include <stdexcept>

#include "render/bvh_backend.h"
#include "render/device_backend.h"
#include "render/embree_backend.h"

namespace tessera {
namespace {

// Whether a CUDA device is there (asked once per process; makes no context).
bool cuda_present(std::string* why) {
  static const std::string reason = [] {
    std::string r;
    if (cuda_device_count(&r) == 0) return r.empty() ? std::string("no CUDA device") : r;
    return std::string();
  }();
  if (why) *why = reason;
  return reason.empty();
}

}  // namespace

std::string resolve_backend(const std::string& requested, const SceneData* scene, bool light_paths, std::string* why) {
  if (why) why->clear();
  if (requested == "embree" || requested == "bvh" || requested == "emulated-device") return requested;
  if (requested != "cuda" && requested != "auto")
    throw std::runtime_error("--backend " + requested + ": unknown backend (auto, embree, bvh, cuda, emulated-device)");
  std::string reason;
  bool ok = cuda_present(&reason);
  if (ok && scene) {
    reason = device_backend_obstacle(*scene, light_paths, false);
    ok = reason.empty();
  }
  if (requested == "cuda") {
    if (!ok) throw std::runtime_error("--backend cuda: " + reason);
    return "cuda";
  }
  if (ok) return "cuda";
  if (why) *why = "auto: " + reason;
  return "embree";
}

std::unique_ptr<TileBackend> make_tile_backend(const std::string& name, const SceneData& scene, int32_t host_threads,
                                               bool light_paths) {
  if (name == "embree") return std::make_unique<EmbreeBackend>(scene);
  if (name == "bvh") return std::make_unique<BvhBackend>(scene);
  if (name == "emulated-device" || name == "cuda") {
    std::string why;
    std::unique_ptr<DeviceApi> device = name == "cuda" ? open_cuda_device(&why) : open_emulated_device(host_threads);
    if (!device) throw std::runtime_error("--backend " + name + ": " + why);
    why = device_backend_obstacle(scene, light_paths, device->has_media_kernels());
    if (!why.empty()) throw std::runtime_error("--backend " + name + ": " + why);
    return std::make_unique<DeviceBackend>(scene.view(), std::move(device));
  }
  throw std::runtime_error("--backend " + name + ": unknown backend (auto, embree, bvh, cuda, emulated-device)");
}

}  // namespace tessera
