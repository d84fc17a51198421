// The device backend (worker/device_backend.h) on the host-emulated device:
// the scene packed into one buffer (worker/scene_pack.h), the guide uploaded
// per pass, batches of tiles rendered by the CUDA kernel's body and the
// learning returned as integers. Its images equal the portable BVH's on the
// CPU bit for bit (the same per-sample code in the same order), guided or
// not, with textures, images, measured spectra, media and motion, and with
// the scene it was built from gone; so does a farm of device and BVH ranks.
// Backend choice: auto falls back to Embree without a device, cuda refuses
// in one line, and scenes the device cannot hold say why.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>

#include "comm/inproc_transport.h"
#include "guided_helpers.h"
#include "master/farm_master.h"
#include "master/image_output.h"
#include "render_helpers.h"
#include "worker/backends.h"
#include "worker/bvh_backend.h"
#include "worker/device_api.h"
#include "worker/device_backend.h"
#include "worker/farm_worker.h"

namespace tessera {
namespace {

RenderOptions small_options(const SceneData& scene, uint32_t spp) {
  RenderOptions opt;
  opt.progress = false;
  opt.spp = spp;
  opt.max_depth = scene.desc().max_depth;
  opt.sampler = sampler_setup(scene.desc());
  opt.seed = 11;
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

SceneData shipped(const char* name, int w = 32, int h = 24) {
  SceneDesc d = load_pbrt_file(testing::source_dir() + "/scenes/" + name + ".pbrt");
  d.film.xres = w;
  d.film.yres = h;
  return SceneData(std::move(d));
}

TEST(DeviceBackend, EqualsTheBvhOnTheShippedScenes) {
  for (const char* name : {"cornell-box", "door-ajar", "glossy"}) expect_device_equals_bvh(shipped(name), name);
}

TEST(DeviceBackend, EqualsTheBvhWithTexturesSpectraImagesMediaAndMotion) {
  {
    SceneDesc d = load_pbrt_file(testing::source_dir() + "/tests/data/materials.pbrt");
    d.film.xres = 32;
    d.film.yres = 18;
    expect_device_equals_bvh(SceneData(std::move(d)), "materials");
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

// Device ranks take batches of tiles: a farm of BVH and device ranks gives
// the local BVH image and field, bit for bit, and names both backends.
TEST(DeviceBackend, FarmOfDeviceAndBvhRanksEqualsTheLocalImage) {
  const SceneData scene = shipped("door-ajar", 48, 36);
  RenderOptions opt = small_options(scene, 8);
  opt.threads = 1;
  GuideField local_guide = make_guide(scene);
  BvhBackend local_backend(scene);
  const RenderResult local = render(scene, local_backend, opt, &local_guide);

  const int32_t ranks = 3;
  InProcessHub hub(ranks);
  std::vector<std::unique_ptr<Transport>> ends;
  std::vector<std::unique_ptr<GuideField>> guides;
  std::vector<std::unique_ptr<TileBackend>> backends;
  for (int32_t r = 0; r < ranks; ++r) {
    ends.push_back(hub.endpoint(r));
    guides.push_back(std::make_unique<GuideField>(make_guide(scene)));
    backends.push_back(make_tile_backend(r == 1 ? "bvh" : "emulated-device", scene, 1));
  }
  const uint32_t spec = effective_specialisation(scene, opt, true);
  std::vector<std::thread> workers;
  for (int32_t r = 1; r < ranks; ++r)
    workers.emplace_back([&, r] {
      run_farm_worker(*ends[r], *backends[r], make_tile_settings(opt, spec, true), guides[r].get(), true, 1);
    });
  FarmMaster master(*ends[0], *backends[0], 1, true);
  const RenderResult farm = render(scene, master, opt, guides[0].get());
  master.stop();
  for (auto& w : workers) w.join();
  EXPECT_EQ(farm.stats.backend, "bvh+emulated-device");
  expect_same_render(local, farm, "farm");
  for (int32_t r = 0; r < ranks; ++r) EXPECT_TRUE(*guides[r] == local_guide) << "rank " << r;
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
  const bool device = open_cuda_device(&why) != nullptr;
  if (device) GTEST_SKIP() << "a CUDA device is present (tests/gpu covers it)";
  EXPECT_FALSE(why.empty());
  std::string auto_why;
  EXPECT_EQ(resolve_backend("auto", nullptr, false, &auto_why), "embree");
  EXPECT_NE(auto_why.find(why), std::string::npos) << auto_why;
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
