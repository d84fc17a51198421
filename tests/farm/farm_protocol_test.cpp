// The farm protocol in one process (InProcessTransport, ranks as threads):
// any number of ranks renders the same image, counters and guide field as
// the local renderer, bit for bit.
#include <gtest/gtest.h>

#include <thread>

#include "../render/guided_helpers.h"
#include "comm/farm_protocol.h"
#include "comm/scene_wire.h"
#include "in_process_farm.h"

namespace tessera {
namespace {

using testing::FarmGuide;
using testing::FarmRun;
using testing::FarmScene;
using testing::door_ajar;
using testing::expect_same_counters;
using testing::films_identical;
using testing::render_farm;

TEST(FarmProtocol, UnguidedImageIsBitIdenticalForAnyRankCount) {
  FarmScene fs(door_ajar());
  RenderResult local = render(fs.scene, fs.embree, fs.opt);
  for (int32_t ranks : {1, 2, 3}) {
    FarmRun farm = render_farm(fs, ranks, FarmGuide::None, true);
    EXPECT_TRUE(films_identical(farm.result.film, local.film)) << ranks << " ranks";
    expect_same_counters(farm.result.stats.counters, local.stats.counters);
    EXPECT_EQ(farm.result.stats.ranks, ranks);
  }
}

// Light-path splats cross tile borders: the master adds each tile's list in
// tile order, so the image is the local one whatever rank rendered a tile.
TEST(FarmProtocol, LightPathSplatsAreBitIdenticalForAnyRankCount) {
  SceneDesc d = load_pbrt_file(testing::source_dir() + "/tests/data/glass-caustic.pbrt");
  FarmScene fs(std::move(d));
  fs.opt.light_paths = true;
  fs.opt.spp = 6;
  RenderResult local = render(fs.scene, fs.embree, fs.opt);
  ASSERT_FALSE(local.film.splats.empty());
  for (int32_t ranks : {1, 2, 3}) {
    FarmRun farm = render_farm(fs, ranks, FarmGuide::None, true);
    EXPECT_TRUE(films_identical(farm.result.film, local.film)) << ranks << " ranks";
    EXPECT_EQ(farm.result.stats.counters.path.light_splats, local.stats.counters.path.light_splats);
  }
}

TEST(FarmProtocol, SharedGuideGivesTheLocalImageAndFieldOnEveryRank) {
  FarmScene fs(door_ajar());
  auto local_guide = fs.make_guide();
  RenderResult local = render(fs.scene, fs.embree, fs.opt, local_guide.get());
  ASSERT_GT(local.stats.counters.path.guided_samples, 0u);
  for (int32_t ranks : {2, 3}) {
    FarmRun farm = render_farm(fs, ranks, FarmGuide::Table, true);
    EXPECT_TRUE(films_identical(farm.result.film, local.film)) << ranks << " ranks";
    expect_same_counters(farm.result.stats.counters, local.stats.counters);
    for (int32_t r = 0; r < ranks; ++r) EXPECT_TRUE(farm.guides[r]->same_as(*local_guide)) << "rank " << r;
  }
}

// --guide auto's trial renders some passes unguided (and may switch guiding
// off): the workers follow the master's specialisation pass by pass, and
// fold only after guided passes, so the farm still gives the local image.
TEST(FarmProtocol, GuideTrialGivesTheLocalImageAndDecisionForAnyRankCount) {
  FarmScene fs(door_ajar());
  // Two windows (at 32 and 64 spp) and a pass after them.
  fs.opt.spp = 2 * kGuideTrialStartSpp + 2 * kGuideTrialPassesPerMethod * 8 + 8;
  fs.opt.guide_trial = true;
  auto local_guide = fs.make_guide();
  RenderResult local = render(fs.scene, fs.embree, fs.opt, local_guide.get());
  ASSERT_EQ(local.stats.guide_trial.windows_done, 2u);
  for (int32_t ranks : {2, 3}) {
    FarmRun farm = render_farm(fs, ranks, FarmGuide::Table, true);
    EXPECT_TRUE(films_identical(farm.result.film, local.film)) << ranks << " ranks";
    expect_same_counters(farm.result.stats.counters, local.stats.counters);
    EXPECT_EQ(farm.result.stats.guide_trial.state, local.stats.guide_trial.state);
    EXPECT_EQ(farm.result.stats.guide_trial.windows_done, local.stats.guide_trial.windows_done);
    EXPECT_EQ(farm.result.stats.guide_trial.guiding, local.stats.guide_trial.guiding);
    for (int32_t r = 0; r < ranks; ++r) EXPECT_TRUE(farm.guides[r]->same_as(*local_guide)) << "rank " << r;
  }
}

// Each rank renders with its own backend: a farm of the portable BVH and
// Embree ranks gives the local image statistically (not bit for bit: the
// two find hits a few ulps apart), every rank ends with the same field, and
// the stats name both backends.
TEST(FarmProtocol, MixedBackendsAgreeWithTheLocalImage) {
  FarmScene fs(door_ajar());
  fs.opt.spp = 32;
  auto local_guide = fs.make_guide();
  RenderResult local = render(fs.scene, fs.embree, fs.opt, local_guide.get());
  FarmRun farm = render_farm(fs, 3, FarmGuide::Table, true, {"bvh", "embree", "bvh"});
  EXPECT_EQ(farm.result.stats.backend, "bvh+embree");
  EXPECT_EQ(local.stats.backend, "embree");
  EXPECT_EQ(farm.result.stats.counters.samples, local.stats.counters.samples);
  for (const PixelAccum& p : farm.result.film.pixels)
    for (int c = 0; c < 3; ++c) ASSERT_TRUE(std::isfinite(p.sum[c]));
  testing::expect_agree(testing::channel_stats(local.film), testing::channel_stats(farm.result.film), "mixed farm");
  for (int32_t r = 1; r < 3; ++r) EXPECT_TRUE(farm.guides[r]->same_as(*farm.guides[0])) << "rank " << r;
}

TEST(FarmProtocol, GuideSyncOffLetsEachRankLearnAlone) {
  FarmScene fs(door_ajar());
  FarmRun shared = render_farm(fs, 3, FarmGuide::Table, true);
  FarmRun alone = render_farm(fs, 3, FarmGuide::Table, false);
  // Every target reaches every field when shared; alone, a rank's field has
  // only its own tiles' targets.
  uint64_t alone_updates = 0;
  auto updates = [](const Guide& g) {
    GuideStats s;
    g.fill_stats(&s);
    return s.table.updates;
  };
  for (const auto& g : alone.guides) {
    EXPECT_LT(updates(*g), updates(*shared.guides[0]));
    alone_updates += updates(*g);
  }
  EXPECT_GT(alone_updates, 0u);
  for (const PixelAccum& p : alone.result.film.pixels)
    for (int c = 0; c < 3; ++c) ASSERT_TRUE(std::isfinite(p.sum[c]));
  EXPECT_EQ(alone.result.stats.counters.samples, shared.result.stats.counters.samples);
}

// The network trained data-parallel: every rank computes fixed-point
// gradients of its own tiles, the master sums them, and every rank takes
// the same Adam steps. The farm's image, and every rank's weights and Adam
// state, equal the local render's bit for bit, for any rank count.
TEST(FarmProtocol, NeuralGuideGivesTheLocalImageAndWeightsOnEveryRank) {
  FarmScene fs(door_ajar());
  auto local_guide = fs.make_neural();
  RenderResult local = render(fs.scene, fs.embree, fs.opt, local_guide.get());
  ASSERT_GT(local.stats.counters.path.guided_samples, 0u);
  ASSERT_GT(local_guide->stats().steps, 0u);
  for (int32_t ranks : {1, 2, 3}) {
    FarmRun farm = render_farm(fs, ranks, FarmGuide::Neural, true);
    EXPECT_TRUE(films_identical(farm.result.film, local.film)) << ranks << " ranks";
    expect_same_counters(farm.result.stats.counters, local.stats.counters);
    for (int32_t r = 0; r < ranks; ++r) EXPECT_TRUE(farm.guides[r]->same_as(*local_guide)) << "rank " << r;
  }
}

// --guide-sync off with the network: every rank trains on its own tiles
// only (its own rounds, nothing reduced), so the ranks' weights differ;
// the image stays finite and every sample is rendered.
TEST(FarmProtocol, NeuralGuideSyncOffLetsEachRankTrainAlone) {
  FarmScene fs(door_ajar());
  FarmRun shared = render_farm(fs, 3, FarmGuide::Neural, true);
  FarmRun alone = render_farm(fs, 3, FarmGuide::Neural, false);
  for (const auto& g : alone.guides) {
    const auto& n = dynamic_cast<const NeuralGuide&>(*g);
    EXPECT_GT(n.stats().steps, 0u);
    EXPECT_LT(n.stats().targets, dynamic_cast<const NeuralGuide&>(*shared.guides[0]).stats().targets);
  }
  EXPECT_FALSE(alone.guides[1]->same_as(*alone.guides[2]));
  for (const PixelAccum& p : alone.result.film.pixels)
    for (int c = 0; c < 3; ++c) ASSERT_TRUE(std::isfinite(p.sum[c]));
  EXPECT_EQ(alone.result.stats.counters.samples, shared.result.stats.counters.samples);
}

TEST(FarmProtocol, SceneSurvivesTheWire) {
  SceneDesc d = door_ajar();
  d.warnings.push_back("x:1: a warning");
  SceneDesc back = decode_scene(encode_scene(d));
  SceneData a(std::move(d)), b(std::move(back));
  EXPECT_EQ(a.fingerprint(), b.fingerprint());
  EXPECT_EQ(a.desc().film.xres, b.desc().film.xres);
  EXPECT_EQ(a.desc().warnings, b.desc().warnings);
  Bytes garbage{1, 2, 3};
  EXPECT_THROW(decode_scene(garbage), std::runtime_error);
  // A crop, shapes that receive a light's power whole, the integrator.
  SceneDesc e = load_pbrt_string(
      "Film \"rgb\" \"integer xresolution\" 40 \"integer yresolution\" 30 \"float cropwindow\" [ 0.3 0.75 0.1 0.55 ]\n"
      "Integrator \"path\"\nWorldBegin\nAreaLightSource \"diffuse\" \"float power\" 10\nShape \"sphere\"\n"
      "Shape \"bilinearmesh\" \"point3 P\" [ 0 0 0  1 0 0  0 1 0  1 1 0 ]\n",
      "wire.pbrt", ".");
  SceneDesc e_back = decode_scene(encode_scene(e));
  for (size_t i = 0; i < e.meshes.size(); ++i) {
    EXPECT_EQ(e.meshes[i].triangles_per_shape, e_back.meshes[i].triangles_per_shape);
    EXPECT_EQ(e.meshes[i].shape_area, e_back.meshes[i].shape_area);
  }
  SceneData c(std::move(e)), d_back(std::move(e_back));
  EXPECT_NE(c.film_fingerprint(), 0u);
  EXPECT_EQ(c.film_fingerprint(), d_back.film_fingerprint());
  EXPECT_EQ(c.fingerprint(), d_back.fingerprint());
  EXPECT_EQ(d_back.view().camera.film_width, 18);
  EXPECT_FALSE(d_back.view().layered_mis_balance);
  EXPECT_EQ(c.view().lights[0].L, d_back.view().lights[0].L);
  // The camera's projection and screen window, curve tubes' one-way faces,
  // a portal, a subsurface medium.
  SceneDesc f = load_pbrt_string(
      "Camera \"orthographic\" \"float screenwindow\" [ -2 2 -1 1 ] \"float frameaspectratio\" 2\nWorldBegin\n"
      "LightSource \"infinite\" \"point3 portal\" [ 0 1 0  1 1 0  1 1 1  0 1 1 ]\n"
      "Shape \"curve\" \"point3 P\" [ 0 0 0  1 0 0  2 0 0  3 0 0 ] \"string type\" \"cylinder\"\n"
      "Material \"subsurface\"\nShape \"sphere\"\n",
      "wire2.pbrt", ".");
  SceneDesc f_back = decode_scene(encode_scene(f));
  EXPECT_EQ(f_back.camera.projection, CameraProjection::Orthographic);
  EXPECT_TRUE(f_back.camera.has_screen_window);
  EXPECT_EQ(f_back.camera.screen_window, f.camera.screen_window);
  EXPECT_EQ(f_back.camera.frame_aspect_ratio, 2.f);
  EXPECT_TRUE(f_back.meshes[0].invisible_from_inside);
  EXPECT_EQ(f_back.meshes[1].media.inside, f.meshes[1].media.inside);
  SceneData g(std::move(f)), g_back(std::move(f_back));
  EXPECT_EQ(g.fingerprint(), g_back.fingerprint());
  EXPECT_EQ(g.film_fingerprint(), g_back.film_fingerprint());
  EXPECT_EQ(g.view().lights[0].portal_area, g_back.view().lights[0].portal_area);
  EXPECT_TRUE(g_back.view().has_one_way_faces);
}

TEST(FarmProtocol, WorkerFailureReachesTheMaster) {
  FarmScene fs(door_ajar());
  InProcessHub hub(2);
  auto master_end = hub.endpoint(0), worker_end = hub.endpoint(1);
  std::thread worker([&] {
    // A worker that says hello and then fails on its first pass.
    worker_end->send(0, kTagHello, encode(FarmHello{1, "embree"}));
    worker_end->receive(0);
    worker_end->send(0, kTagError, encode(FarmError{"out of device memory"}));
    while (worker_end->receive(0).tag != kTagStop) {
    }
    worker_end->send(0, kTagBye, {});
  });
  FarmMaster master(*master_end, fs.embree, FarmMasterOptions{});
  try {
    render(fs.scene, master, fs.opt);
    ADD_FAILURE() << "the render should fail";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("rank 1: out of device memory"), std::string::npos) << e.what();
  }
  EXPECT_TRUE(master.finish().empty());
  worker.join();
}

}  // namespace
}  // namespace tessera
