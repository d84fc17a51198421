// The device backend (render/device_backend.h) on the host-emulated device:
// the scene packed into one buffer (render/scene_pack.h), the guide uploaded
// per pass, batches of tiles rendered by the CUDA kernel's body and the
// learning returned as integers. Its images equal the portable BVH's on the
// CPU bit for bit (the same per-sample code in the same order), guided or
// not (the table or the network), with textures, images, measured spectra,
// media and motion, and with the scene it was built from gone; so does a
// farm of device and BVH ranks.
// Backend choice: auto falls back to Embree without a device, cuda refuses
// in one line, and scenes the device cannot hold say why.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <memory>

#include "comm/inproc_transport.h"
#include "guidecache/neural/neural_guide.h"
#include "guided_helpers.h"
#include "master/farm_master.h"
#include "render/image_output.h"
#include "render_helpers.h"
#include "render/backends.h"
#include "render/bvh_backend.h"
#include "render/bvh_build.h"
#include "render/device_api.h"
#include "render/device_backend.h"
#include "worker/farm_worker.h"
#include "render/scene_pack.h"

namespace tessera {
namespace {

RenderOptions small_options(const SceneData& scene, uint32_t spp) {
  RenderOptions opt = testing::scene_options(scene, spp, 11);
  opt.threads = 2;
  opt.force_full_specialisation = true;  // both backends run the full integrator
  return opt;
}

GuideField make_guide(const SceneData& scene) {
  return GuideField(GuideConfig{}, scene.bounds().lo, scene.bounds().hi, scene.view().num_lights,
                    scene.max_emitted_radiance());
}

void expect_same_render(const RenderResult& a, const RenderResult& b, const std::string& what) {
  EXPECT_TRUE(testing::films_identical(a.film, b.film)) << what;
  EXPECT_EQ(a.stats.counters.samples, b.stats.counters.samples) << what;
  EXPECT_EQ(a.stats.counters.path.rays, b.stats.counters.path.rays) << what;
  EXPECT_EQ(a.stats.counters.path.shadow_rays, b.stats.counters.path.shadow_rays) << what;
  EXPECT_EQ(a.stats.counters.path.guide_updates, b.stats.counters.path.guide_updates) << what;
  EXPECT_EQ(a.stats.counters.zero_radiance, b.stats.counters.zero_radiance) << what;
}

// The BVH backend and the emulated device on one scene, unguided and guided.
void expect_device_equals_bvh(const SceneData& scene, const std::string& what, uint32_t spp = 6) {
  const RenderOptions opt = small_options(scene, spp);
  BvhBackend bvh(scene);
  std::unique_ptr<TileBackend> device = make_tile_backend("emulated-device", scene, 2);
  const RenderResult b = render(scene, bvh, opt), d = render(scene, *device, opt);
  EXPECT_EQ(d.stats.backend, "emulated-device");
  expect_same_render(b, d, what);
  for (const PixelAccum& p : d.film.pixels)
    for (int c = 0; c < 3; ++c) ASSERT_TRUE(std::isfinite(p.sum[c])) << what;
  GuideField gb = make_guide(scene), gd = make_guide(scene);
  const RenderResult bg = render(scene, bvh, opt, &gb), dg = render(scene, *device, opt, &gd);
  ASSERT_GT(dg.stats.counters.path.guide_updates, 0u) << what;
  expect_same_render(bg, dg, what + " (guided)");
  EXPECT_TRUE(gb == gd) << what << ": the device's learning came back different";
}

SceneData shipped(const char* name, int w = 32, int h = 24) { return testing::shipped_scene(name, w, h); }

TEST(DeviceBackend, EqualsTheBvhOnTheShippedScenes) {
  for (const char* name : {"cornell-box", "door-ajar", "glossy"}) expect_device_equals_bvh(shipped(name), name);
}

TEST(DeviceBackend, EqualsTheBvhWithTexturesSpectraImagesMediaAndMotion) {
  for (const bool spectral : {false, true}) {
    SceneDesc d = load_pbrt_file(testing::source_dir() + "/tests/data/materials.pbrt");
    d.film.xres = 32;
    d.film.yres = 18;
    d.spectral = spectral;  // the spectral tables and measured spectra go to the device too
    const SceneData scene(std::move(d));
    ASSERT_EQ(scene.view().spectral.enabled, spectral);
    expect_device_equals_bvh(scene, spectral ? "materials (spectral)" : "materials");
  }
  // An image environment (its texels and sampling distribution), a medium,
  // cut-outs, a one-way curve tube and a moving triangle.
  const testing::TempFile sky("device_sky.exr");
  std::vector<float> texels;
  for (int i = 0; i < 8 * 8; ++i) texels.insert(texels.end(), {0.2f + 0.1f * (i % 8), 0.5f, 1.5f - 0.15f * (i / 8)});
  write_exr(sky.path(), ImageRgb{8, 8, texels}, nullptr, {});  // pbrt-v4's skies are square (equal-area octahedral)
  const std::string scene = R"(
LookAt 0 0 5  0 0 0  0 1 0
Camera "perspective" "float fov" [ 40 ]
Film "rgb" "integer xresolution" [ 24 ] "integer yresolution" [ 24 ]
Integrator "volpath" "integer maxdepth" [ 6 ]
WorldBegin
LightSource "infinite" "string filename" [ ")" + sky.path() + R"(" ]
Texture "checks" "float" "checkerboard" "float uscale" 8 "float vscale" 8 "float tex1" 0 "float tex2" 1
Shape "trianglemesh" "point3 P" [ -2 -2 -1  2 -2 -1  2 2 -1  -2 2 -1 ] "integer indices" [ 0 1 2 0 2 3 ]
  "point2 uv" [ 0 0 1 0 1 1 0 1 ] "texture alpha" "checks"
Shape "curve" "point3 P" [ -1 -1 0  -0.3 1 0.5  0.3 -1 -0.5  1 1 0 ] "float width" 0.4 "string type" "cylinder"
AttributeBegin
MakeNamedMedium "fog" "string type" "homogeneous" "rgb sigma_a" [ 0.2 0.3 0.4 ] "rgb sigma_s" [ 1 1 1 ]
MediumInterface "fog" ""
Material "interface"
Translate 0 -0.8 0.5
Shape "sphere" "float radius" 0.6
AttributeEnd
AttributeBegin
ActiveTransform EndTime
Translate 0.5 0 0
ActiveTransform All
Shape "trianglemesh" "point3 P" [ -1 -1 1  1 -1 1  0 1 1 ]
AttributeEnd
)";
  SceneData data(load_pbrt_string(scene, "device.pbrt", "."));
  ASSERT_TRUE(data.view().media && data.view().positions_end && data.view().triangle_alpha && data.view().num_images > 0);
  expect_device_equals_bvh(data, "image sky, medium, cut-outs, tube, motion", 4);
}

// Every array of the packed view lies in the buffer and holds what the
// scene's own view points to (a pointer left behind would read host memory
// on the GPU), nested ones (images, environment distributions) included.
class PackedPointers {
 public:
  PackedPointers(const unsigned char* lo, size_t size) : lo_(lo), hi_(lo + size) {}
  template <class T>
  void expect(const T* original, const T* packed, size_t n, const char* what) {
    ++checked;
    if (original == nullptr || n == 0) {
      EXPECT_TRUE(packed == nullptr || n == 0) << what;
      return;
    }
    const auto* p = reinterpret_cast<const unsigned char*>(packed);
    ASSERT_TRUE(p >= lo_ && p + n * sizeof(T) <= hi_) << what << " points outside the packed buffer";
    EXPECT_EQ(std::memcmp(original, packed, n * sizeof(T)), 0) << what << " differs from the scene's";
  }
  int checked = 0;

 private:
  const unsigned char *lo_, *hi_;
};

void expect_packed_completely(const SceneData& scene, const std::string& what) {
  const SceneView& o = scene.view();
  const BvhBuild bvh = build_bvh(o);
  const PackedScene packed(o, bvh.view());
  std::vector<unsigned char> buffer(packed.size() + 16);
  unsigned char* at = buffer.data() + (16 - reinterpret_cast<uintptr_t>(buffer.data()) % 16) % 16;
  packed.write_for(reinterpret_cast<uintptr_t>(at), at);
  const SceneView v = packed.view_at(reinterpret_cast<uintptr_t>(at));
  const BvhView b = packed.bvh_at(reinterpret_cast<uintptr_t>(at));
  PackedPointers c(at, packed.size());
  SCOPED_TRACE(what);
  const size_t tris = o.num_triangles;
  c.expect(o.positions, v.positions, o.num_vertices, "positions");
  c.expect(o.normals, v.normals, o.num_normals, "normals");
  c.expect(o.positions_end, v.positions_end, o.num_vertices, "positions_end");
  c.expect(o.normals_end, v.normals_end, o.num_normals, "normals_end");
  c.expect(o.uvs, v.uvs, o.num_uvs, "uvs");
  c.expect(o.indices, v.indices, 3 * tris, "indices");
  c.expect(o.triangles, v.triangles, tris, "triangles");
  c.expect(o.face_normals, v.face_normals, tris, "face_normals");
  c.expect(o.triangle_alpha, v.triangle_alpha, tris, "triangle_alpha");
  c.expect(o.materials, v.materials, o.num_materials, "materials");
  c.expect(o.textures, v.textures, o.num_textures, "textures");
  for (uint32_t i = 0; i < o.num_images; ++i)
    c.expect(o.images[i].texels, v.images[i].texels, size_t(o.images[i].width) * o.images[i].height, "image texels");
  c.expect(o.lights, v.lights, o.num_lights, "lights");
  c.expect(o.light_select.func, v.light_select.func, o.light_select.n, "light_select.func");
  c.expect(o.light_select.cdf, v.light_select.cdf, o.light_select.n + 1, "light_select.cdf");
  c.expect(o.infinite_lights, v.infinite_lights, o.num_infinite_lights, "infinite_lights");
  c.expect(o.light_bvh.nodes, v.light_bvh.nodes, o.light_bvh.num_nodes, "light_bvh.nodes");
  c.expect(o.light_bvh.leaf_of_light, v.light_bvh.leaf_of_light, o.num_lights, "light_bvh.leaf_of_light");
  c.expect(o.light_bvh.unbounded, v.light_bvh.unbounded, o.light_bvh.num_unbounded, "light_bvh.unbounded");
  for (uint32_t i = 0; o.env_distributions && i < o.num_lights; ++i) {
    const Distribution2DView &e = o.env_distributions[i], &p = v.env_distributions[i];
    c.expect(e.func, p.func, size_t(e.width) * e.height, "env func");
    c.expect(e.cond_cdf, p.cond_cdf, size_t(e.width + 1) * e.height, "env cond_cdf");
    c.expect(e.cond_integral, p.cond_integral, e.height, "env cond_integral");
    c.expect(e.marginal.func, p.marginal.func, e.marginal.n, "env marginal func");
    c.expect(e.marginal.cdf, p.marginal.cdf, e.marginal.n + 1, "env marginal cdf");
  }
  c.expect(o.media, v.media, o.num_media, "media");
  c.expect(o.triangle_media, v.triangle_media, tris, "triangle_media");
  c.expect(o.filter.inverse_cdf_x, v.filter.inverse_cdf_x, o.filter.n, "filter x");
  c.expect(o.filter.inverse_cdf_y, v.filter.inverse_cdf_y, o.filter.n, "filter y");
  c.expect(o.filter.weight_x, v.filter.weight_x, o.filter.bins, "filter weight x");
  c.expect(o.filter.weight_y, v.filter.weight_y, o.filter.bins, "filter weight y");
  if (o.spectral.enabled) {
    const size_t res = size_t(o.spectral.res);
    c.expect(o.spectral.cmf, v.spectral.cmf, 3 * kSpectralSamples, "cmf");
    c.expect(o.spectral.illuminant, v.spectral.illuminant, kSpectralSamples, "illuminant");
    c.expect(o.spectral.table_scale, v.spectral.table_scale, res, "table_scale");
    c.expect(o.spectral.table, v.spectral.table, 9 * res * res * res, "rgb-to-spectrum table");
  }
  c.expect(o.spectra, v.spectra, size_t(o.num_spectra) * kSpectralSamples, "spectra");
  c.expect(bvh.view().nodes, b.nodes, bvh.nodes.size(), "bvh nodes");
  c.expect(bvh.view().triangles, b.triangles, bvh.triangles.size(), "bvh triangles");
  EXPECT_GE(c.checked, 30);
}

TEST(PackedScene, EveryArrayLandsInTheBufferWithItsContents) {
  for (const bool spectral : {false, true}) {
    SceneDesc d = load_pbrt_file(testing::source_dir() + "/tests/data/materials.pbrt");
    d.spectral = spectral;
    expect_packed_completely(SceneData(std::move(d)), spectral ? "materials (spectral)" : "materials");
  }
  expect_packed_completely(shipped("door-ajar"), "door-ajar");
  // Measured spectra (a dispersive glass) are packed too.
  SceneDesc glass = load_pbrt_string(R"(
LookAt 0 0 5  0 0 0  0 1 0
Camera "perspective" "float fov" [ 40 ]
Film "rgb" "integer xresolution" [ 8 ] "integer yresolution" [ 8 ]
WorldBegin
LightSource "infinite"
Material "dielectric" "spectrum eta" "glass-BK7"
Shape "sphere" "float radius" 0.6
)", "glass.pbrt", ".");
  glass.spectral = true;
  const SceneData dispersive(std::move(glass));
  ASSERT_GT(dispersive.view().num_spectra, 0u);
  expect_packed_completely(dispersive, "dispersive glass");
}

// The device holds its own copy: the scene it was built from may go.
TEST(DeviceBackend, RendersWithTheSceneItWasBuiltFromGone) {
  SceneData scene = shipped("door-ajar");
  std::unique_ptr<TileBackend> device;
  {
    SceneData original = shipped("door-ajar");
    device = make_tile_backend("emulated-device", original, 2);
  }
  BvhBackend bvh(scene);
  const RenderOptions opt = small_options(scene, 4);
  expect_same_render(render(scene, bvh, opt), render(scene, *device, opt), "door-ajar");
}

// A backend that counts the samples it rendered (so a farm test knows every rank took part).
class CountingBackend : public TileBackend {
 public:
  explicit CountingBackend(std::unique_ptr<TileBackend> inner) : inner_(std::move(inner)) {}
  std::string name() const override { return inner_->name(); }
  bool serves_full_integrator() const override { return inner_->serves_full_integrator(); }
  // Few tiles per request, so that every rank of a small farm gets some.
  uint32_t tiles_per_request(int32_t) const override { return 2; }
  void begin_pass(const TileSettings& s) override { inner_->begin_pass(s); }
  TileCounters render_tiles(TileQueue& q, int32_t threads) override {
    const TileCounters c = inner_->render_tiles(q, threads);
    samples += c.samples;
    return c;
  }
  void end_pass() override { inner_->end_pass(); }
  uint64_t samples = 0;

 private:
  std::unique_ptr<TileBackend> inner_;
};

// A farm over the in-process transport: rank 0 (the master) renders on
// backends[0], the others are workers; each rank has its own guide.
RenderResult render_farm(const SceneData& scene, const RenderOptions& opt, const std::vector<Guide*>& guides,
                         const std::vector<TileBackend*>& backends) {
  const int32_t ranks = static_cast<int32_t>(guides.size());
  InProcessHub hub(ranks);
  std::vector<std::unique_ptr<Transport>> ends;
  for (int32_t r = 0; r < ranks; ++r) ends.push_back(hub.endpoint(r));
  const uint32_t spec = effective_specialisation(scene, opt, guides[0]);
  std::vector<std::thread> workers;
  // The workers' guides, owned as the worker wants them (it would replace one
  // that missed a fold; none does here): handed back when they are done.
  std::vector<std::unique_ptr<Guide>> owned(static_cast<size_t>(ranks));
  for (int32_t r = 1; r < ranks; ++r) owned[r].reset(guides[r]);
  for (int32_t r = 1; r < ranks; ++r)
    workers.emplace_back([&, r] {
      FarmWorkerOptions options;
      options.scene_fingerprint = scene.fingerprint();
      run_farm_worker(*ends[r], *backends[r], make_tile_settings(opt, spec, true), owned[r], options);
    });
  FarmMasterOptions options;
  options.guide = guides[0];
  options.scene_fingerprint = scene.fingerprint();
  FarmMaster master(*ends[0], *backends[0], options);
  RenderResult farm = render(scene, master, opt, guides[0]);
  master.finish();
  for (auto& w : workers) w.join();
  for (int32_t r = 1; r < ranks; ++r) owned[r].release();
  return farm;
}

// Device ranks take batches of tiles: a farm of a BVH master (one tile at a
// time, answering the workers between tiles) and device workers gives the
// local BVH image and field, bit for bit, and names both backends.
TEST(DeviceBackend, FarmOfDeviceAndBvhRanksEqualsTheLocalImage) {
  const SceneData scene = shipped("door-ajar", 96, 72);
  RenderOptions opt = small_options(scene, 8);
  opt.threads = 1;
  GuideField local_guide = make_guide(scene);
  BvhBackend local_backend(scene);
  const RenderResult local = render(scene, local_backend, opt, &local_guide);

  const int32_t ranks = 3;
  std::vector<std::unique_ptr<GuideField>> guides;
  std::vector<std::unique_ptr<CountingBackend>> backends;
  for (int32_t r = 0; r < ranks; ++r) {
    guides.push_back(std::make_unique<GuideField>(make_guide(scene)));
    backends.push_back(std::make_unique<CountingBackend>(make_tile_backend(r == 0 ? "bvh" : "emulated-device", scene, 1)));
  }
  const RenderResult farm = render_farm(scene, opt, {guides[0].get(), guides[1].get(), guides[2].get()},
                                        {backends[0].get(), backends[1].get(), backends[2].get()});
  EXPECT_EQ(farm.stats.backend, "bvh+emulated-device");
  expect_same_render(local, farm, "farm");
  for (int32_t r = 0; r < ranks; ++r) {
    EXPECT_TRUE(*guides[r] == local_guide) << "rank " << r;
    EXPECT_GT(backends[r]->samples, 0u) << "rank " << r << " rendered nothing";
  }
}

std::unique_ptr<NeuralGuide> make_network(const SceneData& scene, uint32_t tile_targets = 128) {
  NeuralGuideConfig c;
  c.width = 16;
  c.steps_per_pass = 4;
  c.tile_targets = tile_targets;
  return std::make_unique<NeuralGuide>(c, scene.bounds().lo, scene.bounds().hi, scene.max_emitted_radiance(),
                                       scene.view().num_lights);
}

// The network on the device: each path records its learning targets in
// slots of its own, and the backend hands them to the training log in the
// order a CPU thread records them, within the same capacities. So the
// emulated device learns exactly what the BVH backend learns: the same
// weights and the same image, bit for bit, on shelter (whose lights' selection is
// learned too) and door-ajar; also where every target is kept and long
// paths meet the per-path limit (tile_targets beyond any tile's offer), and
// where every sample learns, so that passes hold several learning samples
// per pixel (the device's slots interleave them as a CPU thread does).
TEST(DeviceBackend, NeuralGuidedEqualsTheBvh) {
  for (const char* name : {"shelter", "door-ajar"})
    for (const uint32_t tile_targets : {128u, 100000u, 0u}) {
      const bool every_sample = tile_targets == 0;
      const std::string what = std::string(name) + (every_sample ? ", every sample learns" : ", tile_targets " + std::to_string(tile_targets));
      const SceneData scene = shipped(name, 24, 20);
      RenderOptions opt = small_options(scene, 20);  // 16 single-sample learning passes, then larger ones
      opt.tile_size = 8;
      if (every_sample) opt.guide_learn = GuideLearnSchedule{2, 1, false};  // passes of 1, 1, 2, 4, 8 learning samples
      BvhBackend bvh(scene);
      std::unique_ptr<TileBackend> device = make_tile_backend("emulated-device", scene, 2);
      auto gb = make_network(scene, every_sample ? 128u : tile_targets), gd = make_network(scene, every_sample ? 128u : tile_targets);
      const RenderResult b = render(scene, bvh, opt, gb.get()), d = render(scene, *device, opt, gd.get());
      EXPECT_EQ(d.stats.backend, "emulated-device") << what;
      EXPECT_GT(d.stats.neural_guide.steps, 0u) << what;
      EXPECT_GT(d.stats.neural_guide.targets, 0u) << what;
      EXPECT_GT(d.stats.counters.path.guided_samples, 0u) << what;
      expect_same_render(b, d, what);
      EXPECT_TRUE(*gb == *gd) << what << ": the device's targets trained another network";
      EXPECT_EQ(b.stats.neural_guide.targets, d.stats.neural_guide.targets) << what;
      EXPECT_EQ(b.stats.neural_guide.dropped, d.stats.neural_guide.dropped) << what;
      EXPECT_EQ(b.stats.neural_guide.rejected_nonfinite, d.stats.neural_guide.rejected_nonfinite) << what;
      if (tile_targets > 1000) {
        EXPECT_GT(d.stats.neural_guide.dropped, 0u) << what << ": no path met its limit";
      }
      for (const PixelAccum& p : d.film.pixels)
        for (int c = 0; c < 3; ++c) ASSERT_TRUE(std::isfinite(p.sum[c])) << what;
    }
}

// A farm of a BVH master and device workers with the network: the local
// image and weights, bit for bit (the gradients summed across ranks are
// the same whichever rank rendered which tile).
TEST(DeviceBackend, NeuralFarmOfDeviceAndBvhRanksEqualsTheLocalImage) {
  const SceneData scene = shipped("shelter", 48, 36);
  RenderOptions opt = small_options(scene, 18);
  opt.threads = 1;
  auto local_guide = make_network(scene);
  BvhBackend local_backend(scene);
  const RenderResult local = render(scene, local_backend, opt, local_guide.get());

  const int32_t ranks = 3;
  std::vector<std::unique_ptr<NeuralGuide>> guides;
  std::vector<std::unique_ptr<TileBackend>> backends;
  for (int32_t r = 0; r < ranks; ++r) {
    guides.push_back(make_network(scene));
    backends.push_back(make_tile_backend(r == 0 ? "bvh" : "emulated-device", scene, 1));
  }
  ASSERT_TRUE(effective_specialisation(scene, opt, guides[0].get()) & kSpecNeural);
  const RenderResult farm = render_farm(scene, opt, {guides[0].get(), guides[1].get(), guides[2].get()},
                                        {backends[0].get(), backends[1].get(), backends[2].get()});
  EXPECT_EQ(farm.stats.backend, "bvh+emulated-device");
  expect_same_render(local, farm, "neural farm");
  for (int32_t r = 0; r < ranks; ++r) EXPECT_TRUE(*guides[r] == *local_guide) << "rank " << r;
}

// A device that takes a while: finished() says no a few times per launch.
class SlowDevice : public DeviceApi {
 public:
  explicit SlowDevice(std::unique_ptr<DeviceApi> inner) : inner_(std::move(inner)) {}
  std::string backend_name() const override { return inner_->backend_name(); }
  std::string description() const override { return inner_->description(); }
  bool has_media_kernels() const override { return inner_->has_media_kernels(); }
  void* alloc(size_t bytes) override { return inner_->alloc(bytes); }
  void release(void* p) noexcept override { inner_->release(p); }
  void upload(void* d, const void* s, size_t n) override { inner_->upload(d, s, n); }
  void download(void* d, const void* s, size_t n) override { inner_->download(d, s, n); }
  void zero(void* d, size_t n) override { inner_->zero(d, n); }
  void start(const DeviceLaunch& l, uint32_t spec) override {
    inner_->start(l, spec);
    busy_ = 3;
    ++launches;
  }
  bool finished() override {
    if (busy_ == 0) return true;
    --busy_;
    return false;
  }
  void wait() override {
    ASSERT_EQ(busy_, 0) << "wait() before finished() said yes";
    inner_->wait();
  }
  int launches = 0;

 private:
  std::unique_ptr<DeviceApi> inner_;
  int busy_ = 0;
};

// Tiles of a film, counting the calls between tiles.
class CountingTiles : public TileQueue {
 public:
  CountingTiles(Film& film, const std::vector<TileJob>& jobs) : film_(film), jobs_(jobs) {}
  bool take(TileTask* task) override {
    if (next_ >= jobs_.size()) return false;
    *task = TileTask{jobs_[next_], film_tile(film_, jobs_[next_]), next_};
    ++next_;
    return true;
  }
  void done(const TileTask&, uint64_t, std::vector<Splat>&&) override {}
  void between_tiles() override { ++between; }
  int between = 0;

 private:
  Film& film_;
  const std::vector<TileJob>& jobs_;
  size_t next_ = 0;
};

// While the device renders, the backend keeps calling between_tiles (a
// farm master answers its workers there), and waits only once it is done.
TEST(DeviceBackend, AnswersBetweenTilesWhileTheDeviceRenders) {
  const SceneData scene = shipped("cornell-box");
  const RenderOptions opt = small_options(scene, 4);
  const TileSettings settings = make_tile_settings(opt, effective_specialisation(scene, opt, nullptr), false);
  std::vector<TileJob> jobs;
  for (int32_t y = 0; y < 24; y += 8)
    for (int32_t x = 0; x < 32; x += 8) jobs.push_back(TileJob{x, y, x + 8, y + 8, 0, 4, static_cast<uint32_t>(jobs.size())});
  auto slow = std::make_unique<SlowDevice>(open_emulated_device(2));
  SlowDevice& device = *slow;
  DeviceBackend slow_backend(scene.view(), std::move(slow));
  DeviceBackend plain_backend(scene.view(), open_emulated_device(2));
  Film a(32, 24), b(32, 24);
  CountingTiles qa(a, jobs), qb(b, jobs);
  slow_backend.begin_pass(settings);
  const TileCounters ca = slow_backend.render_tiles(qa, 1);
  slow_backend.end_pass();
  plain_backend.begin_pass(settings);
  plain_backend.render_tiles(qb, 1);
  plain_backend.end_pass();
  EXPECT_EQ(device.launches, 1);
  EXPECT_EQ(qa.between, 1 + 3 + 1);  // before the batch, while the device is busy, before finding no more tiles
  EXPECT_EQ(ca.samples, 32u * 24u * 4u);
  EXPECT_TRUE(testing::films_identical(a, b));
}

TEST(DeviceBackend, ScenesTheDeviceCannotHoldSayWhy) {
  const SceneData plain = shipped("cornell-box");
  EXPECT_EQ(device_backend_obstacle(plain, false, false), "");
  EXPECT_NE(device_backend_obstacle(plain, true, true).find("caustics"), std::string::npos);
  const SceneData fog(load_pbrt_string(R"(
LookAt 0 0 5  0 0 0  0 1 0
Camera "perspective" "float fov" [ 40 ]
Film "rgb" "integer xresolution" [ 8 ] "integer yresolution" [ 8 ]
WorldBegin
LightSource "infinite"
MakeNamedMedium "fog" "string type" "homogeneous"
MediumInterface "fog" ""
Material "interface"
Shape "sphere" "float radius" 0.6
)", "fog.pbrt", "."));
  EXPECT_NE(device_backend_obstacle(fog, false, false).find("participating media"), std::string::npos);
  EXPECT_EQ(device_backend_obstacle(fog, false, true), "");  // the emulated device has media kernels
}

TEST(DeviceBackend, AutoFallsBackToEmbreeAndCudaRefusesWithoutADevice) {
  std::string why;
  const bool device = cuda_device_count(&why) > 0;
  if (device) GTEST_SKIP() << "a CUDA device is present (tests/gpu covers it)";
  EXPECT_FALSE(why.empty());
  std::string auto_why;
  EXPECT_EQ(resolve_backend("auto", nullptr, false, &auto_why), "embree");
  EXPECT_EQ(auto_why.rfind("auto: ", 0), 0u) << auto_why;  // the log says why auto chose Embree
  try {
    resolve_backend("cuda");
    ADD_FAILURE() << "--backend cuda should be refused";
  } catch (const std::runtime_error& e) {
    EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos);
    EXPECT_NE(std::string(e.what()).find("--backend cuda: "), std::string::npos) << e.what();
  }
  EXPECT_EQ(resolve_backend("bvh"), "bvh");
  EXPECT_THROW(resolve_backend("optix"), std::runtime_error);
}

}  // namespace
}  // namespace tessera
