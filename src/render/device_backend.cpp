#include "render/device_backend.h"

#include <algorithm>
#include <chrono>
#include <cstring>
#include <stdexcept>
#include <thread>

#include "guidecache/neural/neural_training_log.h"
#include "render/neural_tile_targets.h"
#include "render/scene_pack.h"

namespace tessera {
namespace {

// A new field in the guide's view must be uploaded in upload_guide (or shown
// not to need it): this fails the build until someone looks.
static_assert(sizeof(GuideView) == 200, "GuideView changed: upload its new arrays in upload_guide, then update this size");
static_assert(sizeof(NeuralGuideView) == 96,
              "NeuralGuideView changed: upload its new arrays in upload_network, then update this size");

// Device memory for the learning targets of one batch (tiles stop joining a
// batch beyond it; the first tile always joins): 544 bytes per learning
// path and each tile's room (neural_tile_capacity, or less), so a batch of
// 256 16x16 tiles holds about 7 learning samples per pixel.
constexpr uint64_t kMaxTargetBytes = uint64_t{256} << 20;

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

// The network's weights and bin directions, frozen for the pass. Its
// learning targets go to per-path sinks on the device (device_tiles.h).
void DeviceBackend::upload_network(const NeuralGuideView& v) {
  Staging st;
  const NeuralLayout layout{v.width, v.table_log2, v.lights};
  const size_t params = st.add(v.params, layout.size());
  const size_t bin_dirs = st.add(v.bin_dirs, v.bin_dirs ? kNeuralBins : 0);
  const size_t bin_dir_soa = st.add(v.bin_dir_soa, v.bin_dir_soa ? 3 * kNeuralBins : 0);
  void* base = network_.reserve(st.bytes().size());
  device_->upload(base, st.bytes().data(), st.bytes().size());
  NeuralGuideView& d = device_settings_.path.neural;
  d = v;
  d.params = at_device(base, params, v.params);
  d.bin_dirs = at_device(base, bin_dirs, v.bin_dirs);
  d.bin_dir_soa = at_device(base, bin_dir_soa, v.bin_dir_soa);
  d.sink = nullptr;  // each device thread has its own
}

void DeviceBackend::begin_pass(const TileSettings& settings) {
  if (settings.path.light_traced_caustics)
    throw std::runtime_error("the " + name() + " backend does not trace caustics from the lights yet");
  settings_ = settings;
  device_settings_ = settings;
  device_settings_.neural_log = nullptr;  // a host object: the targets come back per batch
  const GuideView& g = settings.path.guide;
  const bool neural = (served_specialisation(settings.specialisation) & kSpecNeural) != 0;
  if (neural && settings.path.neural.params == nullptr)
    throw std::logic_error("DeviceBackend: a neural-guided pass without the network's view");
  if (neural) upload_network(settings.path.neural);
  else if (g.acc != nullptr && g.acc_words > 0) upload_guide(g);
  neural_learning_ = neural && settings.neural_log != nullptr;
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
    uint64_t target_paths = 0, target_rooms = 0;  // learning paths and rooms of the batch (neural guide)
    const uint32_t capacity = neural_tile_capacity(settings_.path.neural);
    TileTask task;
    while (tasks.size() < kBatchTiles &&
           (target_paths * kNeuralPathTargets + target_rooms) * sizeof(NeuralTrainingSample) < kMaxTargetBytes &&
           queue.take(&task)) {
      const TileJob& j = task.job;
      DeviceTile t{j, pixels.size()};
      if (neural_learning_) {
        t.first_target_path = target_paths;
        t.learning_samples = job_learning_samples(settings_.learn, j);
        t.keep_prob = neural_tile_keep_prob(settings_, j);
        const uint64_t paths = uint64_t(j.x1 - j.x0) * uint64_t(j.y1 - j.y0) * t.learning_samples;
        t.first_room = target_rooms;
        t.room = static_cast<uint32_t>(std::min<uint64_t>(capacity, paths * kNeuralPathTargets));
        target_paths += paths;
        target_rooms += t.room;
      }
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
    if (target_paths > 0) {
      launch.targets = static_cast<NeuralTrainingSample*>(
          targets_.reserve(target_paths * kNeuralPathTargets * sizeof(NeuralTrainingSample)));
      launch.target_counts = static_cast<uint32_t*>(target_counts_.reserve(target_paths * sizeof(uint32_t)));
      launch.sink_words = static_cast<uint64_t*>(sink_words_.reserve(kDeviceSinkWords * sizeof(uint64_t)));
      launch.tile_targets =
          static_cast<NeuralTrainingSample*>(tile_targets_.reserve(target_rooms * sizeof(NeuralTrainingSample)));
      launch.tile_target_counts = static_cast<uint32_t*>(tile_target_counts_.reserve(2 * tiles.size() * sizeof(uint32_t)));
      device_->zero(launch.target_counts, target_paths * sizeof(uint32_t));
      device_->zero(launch.sink_words, kDeviceSinkWords * sizeof(uint64_t));
    }
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
    if (target_paths > 0) gather_targets(tasks, tiles, target_rooms);
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

// Each tile's targets, as the device gathered them (gather_device_targets:
// a CPU thread's order and capacity), to the pass's training log. The
// batch's rejected and dropped counts go with its first tile.
void DeviceBackend::gather_targets(const std::vector<TileTask>& tasks, const std::vector<DeviceTile>& tiles,
                                   uint64_t rooms) {
  const size_t n = tasks.size();
  std::vector<uint32_t> counts(2 * n);
  uint64_t words[kDeviceSinkWords] = {};
  device_->download(counts.data(), tile_target_counts_.get(), counts.size() * sizeof(uint32_t));
  device_->download(words, sink_words_.get(), sizeof(words));
  // Up to the last tile's kept targets (one copy; the rooms' unused ends come too).
  uint64_t used = 0;
  for (size_t i = 0; i < n; ++i)
    if (counts[i] > 0) used = tiles[i].first_room + std::min(counts[i], tiles[i].room);
  gathered_.resize(rooms);
  if (used > 0) device_->download(gathered_.data(), tile_targets_.get(), used * sizeof(NeuralTrainingSample));
  for (size_t i = 0; i < n; ++i) {
    NeuralSampleSink sink;
    sink.tile = tasks[i].job.index;
    sink.data = gathered_.data() + tiles[i].first_room;
    sink.count = std::min(counts[i], tiles[i].room);
    sink.capacity = tiles[i].room;
    sink.dropped = counts[n + i];
    if (i == 0) {
      sink.rejected_nonfinite = words[0];
      sink.rejected_large = words[1];
      sink.dropped += words[2];
      for (uint32_t k = 0; k < kNeuralMixCandidates; ++k) sink.mix_moments[k] = words[3 + k];
      sink.mix_vertices = words[3 + kNeuralMixCandidates];
      sink.mix_rejected = words[4 + kNeuralMixCandidates];
    }
    settings_.neural_log->add_tile(sink);
  }
}

void DeviceBackend::end_pass() {
  const GuideView& g = settings_.path.guide;
  const bool neural = (served_specialisation(settings_.specialisation) & kSpecNeural) != 0;
  if (in_pass_ && !neural && g.acc != nullptr && g.acc_words > 0) {
    std::vector<uint64_t> learned(g.acc_words);
    device_->download(learned.data(), guide_acc_.get(), learned.size() * sizeof(uint64_t));
    for (size_t i = 0; i < learned.size(); ++i) g.acc[i] += learned[i];  // integers: order-free
  }
  in_pass_ = false;
}

}  // namespace tessera
