// Rendering with the neural guide (--guide neural): the analytic furnace,
// agreement with unguided renders on the hard scenes, bit-identical images
// and weights for any thread count, and exact save/load and resume.
#include <gtest/gtest.h>

#include <sstream>

#include "furnace_scene.h"
#include "guided_helpers.h"
#include "master/checkpoint.h"

namespace tessera {
namespace {

using namespace testing;

constexpr uint64_t kUnguidedSeed = 1000003;

NeuralGuideConfig small_network() {
  NeuralGuideConfig c;
  c.width = 16;
  c.steps_per_pass = 8;
  return c;
}

TEST(NeuralGuided, ClosedSphereFurnaceMatchesTheAnalyticValue) {
  const double expected = expected_furnace(0.5, 5);
  GuidedScene s(load_pbrt_string(furnace_scene(0.5, 5), "<furnace>", "."));
  for (bool nee : {true, false}) {
    auto guide = s.make_neural(small_network());
    RenderOptions opt;
    opt.nee = nee;
    RenderResult r = s.run(guide.get(), opt);
    ChannelStats m = channel_stats(r.film);
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(m.mean[c], expected, 0.01 * expected) << "nee " << nee;
    EXPECT_GT(r.stats.counters.path.guided_samples, 0u);
    EXPECT_GT(r.stats.neural_guide.steps, 0u);
    EXPECT_GT(r.stats.neural_guide.targets, 0u);
    EXPECT_EQ(r.stats.neural_guide.rejected_nonfinite, 0u);
    EXPECT_EQ(r.stats.counters.rejected_nonfinite, 0u);
    EXPECT_EQ(r.stats.guide_mode, "neural");
  }
}

// The hard scenes: guided means agree with unguided ones within their
// confidence interval.
TEST(NeuralGuided, DoorAjarAndShelterAgreeWithUnguided) {
  for (const char* name : {"door-ajar", "shelter"}) {
    SCOPED_TRACE(name);
    GuidedScene s(shipped(name, 40, 30, 192, 8));
    // A pixel's later samples reuse its first site wherever they land on the
    // same surface (NeuralFirstSite, at the largest radius): still unbiased.
    NeuralGuideConfig c = small_network();
    c.reuse_cells = 1e4f;
    auto guide = s.make_neural(c);
    // Shelter's three quad lights (six triangles): selection is learned (and must stay unbiased).
    EXPECT_EQ(guide->learned_lights(), std::string(name) == "shelter" ? 6u : 0u);
    RenderResult g = s.run(guide.get());
    RenderResult u = s.run(nullptr, seeded(kUnguidedSeed));
    ChannelStats mu = channel_stats(u.film);
    expect_precise(mu, 0.05, name);
    expect_agree(channel_stats(g.film), mu, name);
    EXPECT_TRUE(all_finite(g.film));
    EXPECT_GT(g.stats.counters.path.guided_samples, g.stats.counters.path.vertices / 20);
    EXPECT_GT(g.stats.counters.path.neural_sites_reused, g.stats.counters.path.vertices / 10);
    if (guide->learned_lights() > 0) {
      // The render selected lights from the network's distribution (after its first step).
      NeuralSite site;
      neural_infer(guide->view(), 0.5f * (s.scene.bounds().lo + s.scene.bounds().hi), Vec3(0.f, 1.f, 0.f), &site);
      EXPECT_EQ(site.light_prob, kNeuralLightGuideProb);
    }
    EXPECT_GT(g.stats.neural_guide.steps, 0u);
    EXPECT_EQ(g.stats.neural_guide.nonfinite_gradients, 0u);
  }
}

TEST(NeuralGuided, BitIdenticalImageAndWeightsAcrossThreadCounts) {
  GuidedScene s(shipped("shelter", 32, 24, 24, 6));  // 16 single-sample learning passes, then one of 8
  RenderResult results[3];
  std::unique_ptr<NeuralGuide> guides[3];
  const int threads[3] = {1, 2, 4};
  for (int i = 0; i < 3; ++i) {
    NeuralGuideConfig c = small_network();
    c.reuse_cells = 1e4f;  // pixels' samples share first sites (NeuralFirstSite) wherever they may
    guides[i] = s.make_neural(c);
    RenderOptions opt;
    opt.threads = threads[i];
    opt.tile_size = 8;
    opt.seed = 7;
    results[i] = s.run(guides[i].get(), opt);
  }
  EXPECT_GT(guides[0]->stats().steps, 0u);
  // The mixture statistics came through the integrator and the threads' sinks, and chose a weight.
  EXPECT_GT(guides[0]->stats().mix_vertices, 0u);
  EXPECT_NE(guides[0]->mix_candidate(), -1);
  EXPECT_EQ(guides[0]->view().guide_prob, guide_mix_candidate(static_cast<uint32_t>(guides[0]->mix_candidate())));
  // Pixels shared first sites between samples, the same ones whichever thread traced them.
  EXPECT_GT(results[0].stats.counters.path.neural_sites_reused, 0u);
  EXPECT_EQ(results[0].stats.counters.path.neural_sites_reused, results[2].stats.counters.path.neural_sites_reused);
  EXPECT_TRUE(films_identical(results[0].film, results[1].film));
  EXPECT_TRUE(films_identical(results[0].film, results[2].film));
  EXPECT_TRUE(*guides[0] == *guides[1]);
  EXPECT_TRUE(*guides[0] == *guides[2]);
}

// In a scene of Lambertian surfaces and area lights the network runs an
// integrator specialised for them: the same image and network as the full one's.
TEST(NeuralGuided, LambertianSpecialisationEqualsTheFullIntegrator) {
  GuidedScene s(shipped("door-ajar", 32, 24, 12, 6));
  RenderResult results[2];
  std::unique_ptr<NeuralGuide> guides[2];
  for (int i = 0; i < 2; ++i) {
    guides[i] = s.make_neural(small_network());
    RenderOptions opt;
    opt.seed = 5;
    opt.force_full_specialisation = i == 1;
    results[i] = s.run(guides[i].get(), opt);
  }
  EXPECT_EQ(results[0].stats.specialisation, kSpecNeural | kSpecGuiding | kSpecAreaLights);
  EXPECT_EQ(results[1].stats.specialisation & kSpecSurfaceAll, kSpecSurfaceAll);
  EXPECT_TRUE(films_identical(results[0].film, results[1].film));
  EXPECT_TRUE(*guides[0] == *guides[1]);
}

// The network learns in passes of one sample while every sample learns
// (each pass refreshes the network its targets bootstrap from); the table
// keeps the doubling schedule.
TEST(NeuralGuided, LearnsInSingleSamplePassesWhileEverySampleLearns) {
  const uint32_t table[] = {1, 1, 2, 4, 8, 8};
  for (uint32_t p = 0; p < 6; ++p) EXPECT_EQ(pass_spp_for(p, 8), table[p]) << p;
  for (uint32_t p = 0; p < 3; ++p) EXPECT_EQ(pass_spp_for(p, 8, 3), 1u) << p;
  const uint32_t after[] = {2, 4, 8, 8};
  for (uint32_t p = 0; p < 4; ++p) EXPECT_EQ(pass_spp_for(3 + p, 8, 3), after[p]) << p;

  GuidedScene s(shipped("door-ajar", 16, 12, 8, 4));
  RenderOptions opt;
  opt.progress = false;
  opt.spp = 11;
  opt.max_depth = 4;
  opt.guide_learn.all_spp = 4;
  auto guide = s.make_neural(small_network());
  RenderResult r = render(s.scene, s.embree, opt, guide.get());
  std::vector<uint32_t> spp;
  for (const PassStats& p : r.stats.pass_stats) spp.push_back(p.spp);
  EXPECT_EQ(spp, (std::vector<uint32_t>{1, 1, 1, 1, 2, 4, 1}));
  EXPECT_GE(r.stats.neural_guide.pass_loss.size(), 4u);
}

// A saved network renders (and goes on learning) exactly as the one it was saved from.
TEST(NeuralGuided, SavedNetworkRendersTheSameImage) {
  GuidedScene s(shipped("door-ajar", 24, 18, 8, 6));
  auto guide = s.make_neural(small_network());
  s.run(guide.get());
  std::stringstream bytes;
  guide->save(bytes, s.scene.fingerprint());
  std::unique_ptr<Guide> loaded = load_guide(bytes, s.scene.fingerprint());
  ASSERT_TRUE(loaded->same_as(*guide));
  RenderResult a = s.run(guide.get()), b = s.run(loaded.get());
  EXPECT_TRUE(films_identical(a.film, b.film));
  EXPECT_TRUE(loaded->same_as(*guide));
}

// A render stopped after some passes and resumed from its checkpoint (the
// network's weights and Adam's moments inside) ends with the image and the
// weights of an uninterrupted one.
TEST(NeuralGuided, ResumedRenderEqualsTheUninterruptedOne) {
  GuidedScene s(shipped("door-ajar", 24, 18, 24, 6));
  RenderOptions opt;
  opt.progress = false;
  opt.spp = 24;
  opt.max_depth = 6;
  opt.seed = 3;
  auto whole_guide = s.make_neural(small_network());
  RenderResult whole = render(s.scene, s.embree, opt, whole_guide.get());

  auto first_guide = s.make_neural(small_network());
  RenderOptions part = opt;
  part.spp = 4;  // four passes of 1 spp (the network learns in single-sample passes)
  RenderResult first = render(s.scene, s.embree, part, first_guide.get());
  const std::string path = ::testing::TempDir() + "/neural.ckpt";
  write_checkpoint(path, first, first_guide.get(), s.scene.fingerprint(), 11);
  const Checkpoint ck = read_checkpoint(path, s.scene.fingerprint(), 11);
  std::istringstream gs(std::string(ck.guide.begin(), ck.guide.end()));
  std::unique_ptr<Guide> resumed_guide = load_guide(gs, s.scene.fingerprint());
  ASSERT_TRUE(resumed_guide->same_as(*first_guide));
  RenderResult resumed = render(s.scene, s.embree, opt, resumed_guide.get(), &ck.so_far);
  EXPECT_TRUE(films_identical(resumed.film, whole.film));
  EXPECT_TRUE(resumed_guide->same_as(*whole_guide));
}

}  // namespace
}  // namespace tessera
