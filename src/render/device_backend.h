// The GPU backend behind the seam (render/tile_backend.h), over a DeviceApi
// (render/device_api.h): the scene and its BVH live in device memory (one
// PackedScene upload); every pass uploads the guide as it stands after the
// last fold and a zeroed copy of its accumulator block; each batch of tiles
// is a trace (a thread per pixel and sample) and an accumulation (a thread
// per pixel, adding in sample order; no float atomics), whose pixel
// accumulators and counters come back to the host; end_pass
// adds the device's integer accumulators into the pass's block, for the
// fold and the farm's sum over the ranks. With the neural guide, every pass
// uploads the network's weights instead (frozen for the pass), and each
// batch's learning targets come back to the pass's training log, tile by
// tile, the same targets a CPU backend keeps (the host trains between
// passes; guidecache/neural_guide.h).
//
// Served by the full integrator (served_specialisation, as --backend bvh).
// device_backend_obstacle says which scenes cannot go there yet; --backend
// auto then picks Embree.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "render/bvh_build.h"
#include "render/device_api.h"
#include "render/scene_pack.h"
#include "render/scene_data.h"
#include "render/tile_backend.h"

namespace tessera {

// What keeps a scene off the device backend, "" if nothing: grid media
// (not packed yet), caustics traced from the lights (light_paths), and any
// medium where the device has no media kernels (CUDA: they would double the
// build).
std::string device_backend_obstacle(const SceneData& scene, bool light_paths, bool media_kernels);

class DeviceBackend : public TileBackend {
 public:
  // Copies `scene` to the device (it is not read afterwards). Throws
  // std::runtime_error when the scene cannot go to the device or the
  // device's memory is short.
  DeviceBackend(const SceneView& scene, std::unique_ptr<DeviceApi> device);
  // From a scene already packed (with its BVH).
  DeviceBackend(const PackedScene& packed, std::unique_ptr<DeviceApi> device);
  DeviceBackend(const DeviceBackend&) = delete;
  DeviceBackend& operator=(const DeviceBackend&) = delete;

  std::string name() const override { return device_->backend_name(); }
  bool serves_full_integrator() const override { return true; }
  uint32_t tiles_per_request(int32_t threads) const override { return kBatchTiles; }
  void begin_pass(const TileSettings& settings) override;
  TileCounters render_tiles(TileQueue& queue, int32_t threads) override;
  void end_pass() override;

  // Tiles per launch (and per farm request): with a thread per pixel and
  // sample, 256 16x16 tiles are 65,536 threads per sample of the pass;
  // few enough that a farm's other ranks find tiles.
  static constexpr uint32_t kBatchTiles = 256;

 private:
  // A device allocation that grows (never shrinks) as batches need, freed
  // with the backend (or when its constructor fails).
  class Buffer {
   public:
    explicit Buffer(DeviceApi& device) : device_(device) {}
    ~Buffer() { device_.release(ptr_); }
    Buffer(const Buffer&) = delete;
    Buffer& operator=(const Buffer&) = delete;
    void* reserve(size_t bytes);
    void* get() const { return ptr_; }

   private:
    DeviceApi& device_;
    void* ptr_ = nullptr;
    size_t bytes_ = 0;
  };
  void upload_guide(const GuideView& host);
  void upload_network(const NeuralGuideView& host);
  // Hands the batch's learning targets to the pass's training log, tile by tile.
  void gather_targets(const std::vector<TileTask>& tasks, const std::vector<DeviceTile>& tiles, uint64_t rooms);

  std::unique_ptr<DeviceApi> device_;  // declared first: the buffers are freed before it goes
  Buffer scene_bytes_{*device_}, scene_view_{*device_}, guide_bytes_{*device_}, guide_acc_{*device_};
  Buffer tiles_{*device_}, pixels_{*device_}, values_{*device_}, counters_{*device_};
  Buffer network_{*device_}, targets_{*device_}, target_counts_{*device_}, sink_words_{*device_};
  Buffer tile_targets_{*device_}, tile_target_counts_{*device_};
  BvhView bvh_;
  TileSettings settings_;      // the pass's, as the host gave them
  TileSettings device_settings_;  // the same with the guide view in device memory
  bool in_pass_ = false;
  bool neural_learning_ = false;  // this pass records the neural guide's learning targets
  std::vector<NeuralTrainingSample> gathered_;  // a batch's tiles' targets, back from the device
};

}  // namespace tessera
