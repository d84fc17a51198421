// The CUDA backend on a real device (label gpu; every test skips where this
// build has no CUDA backend or the machine no device): the Cornell box and
// door-ajar render on the GPU as on Embree (statistically: nvcc contracts
// multiply-adds, so the bits differ), twice the same bit for bit, guided
// too, with the guide's learning coming back from the device.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <stdexcept>
#include <string>

#include "../render/guided_helpers.h"
#include "../render/render_helpers.h"
#include "render/backends.h"
#include "render/device_api.h"
#include "render/embree_backend.h"

namespace tessera {
namespace {

bool cuda_device_here() {
  std::string why;
  return open_cuda_device(&why) != nullptr;
}

RenderOptions options_for(const SceneData& scene, uint32_t spp) { return testing::scene_options(scene, spp, 5); }

SceneData shipped(const char* name) { return testing::shipped_scene(name, 64, 48); }

TEST(CudaBackend, AgreesWithEmbreeAndRepeatsBitForBit) {
  if (!cuda_device_here()) GTEST_SKIP() << "no CUDA device";
  for (const char* name : {"cornell-box", "door-ajar"}) {
    const SceneData scene = shipped(name);
    RenderOptions opt = options_for(scene, 64);
    EmbreeBackend embree(scene);
    const RenderResult e = render(scene, embree, opt);
    opt.force_full_specialisation = true;
    std::unique_ptr<TileBackend> cuda = make_tile_backend("cuda", scene);
    opt.seed = 6;
    const RenderResult g1 = render(scene, *cuda, opt), g2 = render(scene, *cuda, opt);
    EXPECT_EQ(g1.stats.backend, "cuda");
    EXPECT_TRUE(testing::films_identical(g1.film, g2.film)) << name;
    for (const PixelAccum& p : g1.film.pixels)
      for (int c = 0; c < 3; ++c) ASSERT_TRUE(std::isfinite(p.sum[c])) << name;
    testing::expect_agree(testing::channel_stats(e.film), testing::channel_stats(g1.film), name);
  }
}

// auto takes the device.
TEST(CudaBackend, AutoPicksTheDevice) {
  if (!cuda_device_here()) GTEST_SKIP() << "no CUDA device";
  std::string why;
  EXPECT_EQ(resolve_backend("auto", nullptr, false, &why), "cuda");
  EXPECT_EQ(why, "");
}

TEST(CudaBackend, GuidedRenderLearnsOnTheDevice) {
  if (!cuda_device_here()) GTEST_SKIP() << "no CUDA device";
  const SceneData scene = shipped("door-ajar");
  RenderOptions opt = options_for(scene, 64);
  opt.force_full_specialisation = true;
  std::unique_ptr<TileBackend> cuda = make_tile_backend("cuda", scene);
  auto guide = [&] {
    return GuideField(GuideConfig{}, scene.bounds().lo, scene.bounds().hi, scene.view().num_lights,
                      scene.max_emitted_radiance());
  };
  GuideField a = guide(), b = guide();
  const RenderResult ra = render(scene, *cuda, opt, &a), rb = render(scene, *cuda, opt, &b);
  EXPECT_GT(ra.stats.counters.path.guide_updates, 0u);
  EXPECT_GT(ra.stats.counters.path.guided_samples, 0u);
  EXPECT_TRUE(a == b);
  EXPECT_TRUE(testing::films_identical(ra.film, rb.film));
  EmbreeBackend embree(scene);
  const RenderResult e = render(scene, embree, options_for(scene, 64));
  testing::expect_agree(testing::channel_stats(e.film), testing::channel_stats(ra.film), "door-ajar guided");
}

}  // namespace
}  // namespace tessera
