#include "worker/device_backend.h"

#include <algorithm>
#include <chrono>
#include <cstring>
#include <stdexcept>
#include <thread>

#include "worker/scene_pack.h"

namespace tessera {
namespace {

// A new field in the guide's view must be uploaded in upload_guide (or shown
// not to need it): this fails the build until someone looks.
static_assert(sizeof(GuideView) == 200, "GuideView changed: upload its new arrays in upload_guide, then update this size");

// Host arrays laid out back to back (16-byte aligned) for one upload.
class Staging {
 public:
  template <class T>
  size_t add(const T* data, size_t count) {
    const size_t at = (bytes_.size() + 15) & ~size_t{15};
    bytes_.resize(at + count * sizeof(T));
    if (count > 0) std::memcpy(bytes_.data() + at, data, count * sizeof(T));
    return at;
  }
  const std::vector<unsigned char>& bytes() const { return bytes_; }

 private:
  std::vector<unsigned char> bytes_;
};

template <class T>
const T* at_device(void* base, size_t offset, const T* host) {
  return host ? reinterpret_cast<const T*>(static_cast<unsigned char*>(base) + offset) : nullptr;
}

}  // namespace

std::string device_backend_obstacle(const SceneData& scene, bool light_paths, bool media_kernels) {
  if (scene.view().grids != nullptr) return "the scene has grid media, which the device backend does not hold yet";
  if (scene.view().media != nullptr && !media_kernels)
    return "the scene has participating media, which the CUDA backend does not render yet";
  if (light_paths) return "the scene's caustics are traced from the lights, which the device backend does not do yet";
  return "";
}

namespace {

PackedScene pack_with_bvh(const SceneView& scene) {
  const BvhBuild bvh = build_bvh(scene);
  return PackedScene(scene, bvh.view());  // throws for what a device cannot hold
}

}  // namespace

DeviceBackend::DeviceBackend(const SceneView& scene, std::unique_ptr<DeviceApi> device)
    : DeviceBackend(pack_with_bvh(scene), std::move(device)) {}

DeviceBackend::DeviceBackend(const PackedScene& packed, std::unique_ptr<DeviceApi> device)
    : device_(std::move(device)) {
  void* base = scene_bytes_.reserve(packed.size());
  std::vector<unsigned char> staging(packed.size());
  packed.write_for(reinterpret_cast<uintptr_t>(base), staging.data());
  device_->upload(base, staging.data(), staging.size());
  const SceneView view = packed.view_at(reinterpret_cast<uintptr_t>(base));
  device_->upload(scene_view_.reserve(sizeof(SceneView)), &view, sizeof(SceneView));
  bvh_ = packed.bvh_at(reinterpret_cast<uintptr_t>(base));
}

void* DeviceBackend::Buffer::reserve(size_t bytes) {
  bytes = std::max<size_t>(bytes, 16);
  if (bytes_ >= bytes) return ptr_;
  device_.release(ptr_);
  ptr_ = nullptr;
  bytes_ = 0;
  ptr_ = device_.alloc(bytes);
  bytes_ = bytes;
  return ptr_;
}

// The guide as it stands (frozen for the pass) and a zeroed accumulator
// block: the device's paths add their targets there with integer atomics.
void DeviceBackend::upload_guide(const GuideView& g) {
  const size_t cells = g.num_cells;
  Staging st;
  const size_t nodes = st.add(g.nodes, g.num_nodes);
  const size_t top = st.add(g.top_nodes, g.top_nodes ? size_t{kGuideNormalClasses} * kGuideTopCells : 0);
  const size_t bin_dirs = st.add(g.bin_dirs, g.bins);
  const size_t value = st.add(g.value, cells * g.stride);
  const size_t alias = st.add(g.dir_alias, cells * g.bins);
  const size_t light_cdf = st.add(g.light_cdf, g.light_cdf ? cells * (g.lights + 1) : 0);
  const size_t irradiance = st.add(g.irradiance, cells);
  const size_t qmax = st.add(g.qmax, cells);
  const size_t learn_normal = st.add(g.learn_normal, cells);
  const size_t light_prob = st.add(g.cell_light_prob, g.cell_light_prob ? cells : 0);
  const size_t nee_prob = st.add(g.nee_prob, g.nee_prob ? cells : 0);
  const size_t mix = st.add(g.cell_mix, cells);
  void* base = guide_bytes_.reserve(st.bytes().size());
  device_->upload(base, st.bytes().data(), st.bytes().size());
  uint64_t* acc = static_cast<uint64_t*>(guide_acc_.reserve(g.acc_words * sizeof(uint64_t)));
  device_->zero(acc, g.acc_words * sizeof(uint64_t));

  GuideView& d = device_settings_.path.guide;
  d = g;
  d.nodes = at_device(base, nodes, g.nodes);
  d.top_nodes = at_device(base, top, g.top_nodes);
  d.bin_dirs = at_device(base, bin_dirs, g.bin_dirs);
  d.value = at_device(base, value, g.value);
  d.dir_alias = at_device(base, alias, g.dir_alias);
  d.light_cdf = at_device(base, light_cdf, g.light_cdf);
  d.irradiance = at_device(base, irradiance, g.irradiance);
  d.qmax = at_device(base, qmax, g.qmax);
  d.learn_normal = at_device(base, learn_normal, g.learn_normal);
  d.cell_light_prob = at_device(base, light_prob, g.cell_light_prob);
  d.nee_prob = at_device(base, nee_prob, g.nee_prob);
  d.cell_mix = at_device(base, mix, g.cell_mix);
  d.acc = acc;
  d.acc_normal = acc + (g.acc_normal - g.acc);
  d.rejected = acc + (g.rejected - g.acc);
  d.acc_private = false;  // shared by every device thread: atomic adds
}

void DeviceBackend::begin_pass(const TileSettings& settings) {
  if (settings.path.light_traced_caustics)
    throw std::runtime_error("the " + name() + " backend does not trace caustics from the lights yet");
  if (settings.specialisation & kSpecNeural)
    throw std::runtime_error("the " + name() + " backend has no neural guide yet (--backend embree or bvh has)");
  settings_ = settings;
  device_settings_ = settings;
  const GuideView& g = settings.path.guide;
  if (g.acc != nullptr && g.acc_words > 0) upload_guide(g);
  in_pass_ = true;
}

TileCounters DeviceBackend::render_tiles(TileQueue& queue, int32_t) {
  if (!in_pass_) throw std::logic_error("DeviceBackend: render_tiles outside a pass");
  TileCounters total;
  std::vector<TileTask> tasks;
  std::vector<DeviceTile> tiles;
  std::vector<PixelAccum> pixels;
  for (;;) {
    queue.between_tiles();
    tasks.clear();
    tiles.clear();
    pixels.clear();
    uint32_t max_tile_pixels = 0, max_samples = 0;
    TileTask task;
    while (tasks.size() < kBatchTiles && queue.take(&task)) {
      const TileJob& j = task.job;
      DeviceTile t{j, pixels.size()};
      for (int32_t y = j.y0; y < j.y1; ++y)
        for (int32_t x = j.x0; x < j.x1; ++x) pixels.push_back(task.pixels.at(j, x, y));
      max_tile_pixels = std::max(max_tile_pixels, static_cast<uint32_t>(pixels.size() - t.first_pixel));
      max_samples = std::max(max_samples, tile_samples(t));
      tiles.push_back(t);
      tasks.push_back(task);
    }
    if (tasks.empty()) break;
    DeviceLaunch launch;
    launch.scene = static_cast<const SceneView*>(scene_view_.get());
    launch.bvh = bvh_;
    launch.settings = device_settings_;
    launch.num_tiles = static_cast<uint32_t>(tiles.size());
    launch.max_tile_pixels = max_tile_pixels;
    launch.max_samples = max_samples;
    auto* d_tiles = static_cast<DeviceTile*>(tiles_.reserve(tiles.size() * sizeof(DeviceTile)));
    auto* d_pixels = static_cast<PixelAccum*>(pixels_.reserve(pixels.size() * sizeof(PixelAccum)));
    auto* d_values = static_cast<Rgb*>(values_.reserve(pixels.size() * max_samples * sizeof(Rgb)));
    auto* d_counters = static_cast<TileCounters*>(counters_.reserve(sizeof(TileCounters)));
    device_->upload(d_tiles, tiles.data(), tiles.size() * sizeof(DeviceTile));
    device_->upload(d_pixels, pixels.data(), pixels.size() * sizeof(PixelAccum));
    device_->zero(d_counters, sizeof(TileCounters));
    launch.tiles = d_tiles;
    launch.pixels = d_pixels;
    launch.values = d_values;
    launch.counters = d_counters;
    device_->start(launch, served_specialisation(settings_.specialisation));
    // A farm master answers its workers while the device renders.
    while (!device_->finished()) {
      queue.between_tiles();
      std::this_thread::sleep_for(std::chrono::microseconds(50));
    }
    device_->wait();
    device_->download(pixels.data(), d_pixels, pixels.size() * sizeof(PixelAccum));
    TileCounters batch;
    device_->download(&batch, d_counters, sizeof(TileCounters));
    total.add(batch);
    for (size_t i = 0; i < tasks.size(); ++i) {
      const TileJob& j = tasks[i].job;
      size_t k = tiles[i].first_pixel;
      for (int32_t y = j.y0; y < j.y1; ++y)
        for (int32_t x = j.x0; x < j.x1; ++x) tasks[i].pixels.at(j, x, y) = pixels[k++];
      const uint64_t samples = static_cast<uint64_t>(j.x1 - j.x0) * static_cast<uint64_t>(j.y1 - j.y0) *
                               (j.sample_end - j.sample_begin);
      queue.done(tasks[i], samples, {});
    }
  }
  return total;
}

void DeviceBackend::end_pass() {
  const GuideView& g = settings_.path.guide;
  if (in_pass_ && g.acc != nullptr && g.acc_words > 0) {
    std::vector<uint64_t> learned(g.acc_words);
    device_->download(learned.data(), guide_acc_.get(), learned.size() * sizeof(uint64_t));
    for (size_t i = 0; i < learned.size(); ++i) g.acc[i] += learned[i];  // integers: order-free
  }
  in_pass_ = false;
}

}  // namespace tessera
