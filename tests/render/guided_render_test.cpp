// Guided rendering through the library: the image stays unbiased (analytic
// furnace values, agreement with unguided renders within a confidence
// interval), degenerate guides stay stable, and guided renders are
// bit-identical across thread counts, guide cache included.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <sstream>

#include "render_helpers.h"
#include "scene/builtin_scenes.h"

namespace tessera {
namespace {

// One scene + its Embree BVH, rendered with or without a guide.
struct GuidedSetup {
  SceneData scene;
  EmbreeScene embree;
  explicit GuidedSetup(SceneDesc d) : scene(std::move(d)), embree(scene) {}

  GuideField make_guide(GuideTarget target = GuideTarget::ExpectedSarsa) const {
    GuideConfig cfg;
    cfg.target = target;
    return GuideField(cfg, scene.bounds().lo, scene.bounds().hi, scene.view().num_lights,
                      scene.max_emitted_radiance());
  }
  // Unguided renders use another seed than guided ones, so that comparisons
  // between them are between independent estimates.
  RenderResult run(GuideField* guide, RenderOptions opt = {}) const {
    opt.progress = false;
    if (!guide) opt.seed += 1000003;
    opt.spp = static_cast<uint32_t>(scene.desc().spp);
    opt.max_depth = scene.desc().max_depth;
    return render(scene, embree, opt, guide);
  }
};

// Mean over pixels and channels and its standard error, from the per-pixel
// variance of the mean that the film keeps. Pixels are independent; the
// channels of one pixel are not, so their errors add as if fully correlated
// (the conservative bound).
struct MeanAndError {
  double mean = 0, se = 0;
};
MeanAndError image_mean_and_error(const Film& film) {
  ImageRgb m = film_mean(film), v = film_variance_of_mean(film);
  double sum = 0, var[3] = {0, 0, 0};
  for (size_t i = 0; i < m.rgb.size(); ++i) {
    sum += m.rgb[i];
    var[i % 3] += v.rgb[i];
  }
  const double pixels = static_cast<double>(m.rgb.size() / 3);
  const double se = (std::sqrt(var[0]) + std::sqrt(var[1]) + std::sqrt(var[2])) / (3.0 * pixels);
  return {sum / (3.0 * pixels), se};
}

// Guided and unguided means agree within 4 combined standard errors
// (a false alarm has probability ~6e-5).
void expect_agree(const MeanAndError& a, const MeanAndError& b) {
  const double tol = 4.0 * std::sqrt(a.se * a.se + b.se * b.se);
  EXPECT_NEAR(a.mean, b.mean, tol) << "standard errors " << a.se << ", " << b.se;
}

bool all_finite(const Film& film) {
  for (float v : film_mean(film).rgb)
    if (!std::isfinite(v)) return false;
  return true;
}

bool films_identical(const Film& a, const Film& b) {
  if (a.width != b.width || a.height != b.height) return false;
  for (size_t i = 0; i < a.pixels.size(); ++i)
    if (std::memcmp(&a.pixels[i], &b.pixels[i], sizeof(PixelAccum)) != 0) return false;
  return true;
}

SceneDesc furnace(double rho, int max_depth) {
  char buf[1024];
  std::snprintf(buf, sizeof buf, R"(
LookAt 0 0 0  0 0 1  0 1 0
Camera "perspective" "float fov" [ 60 ]
Film "rgb" "integer xresolution" [ 16 ] "integer yresolution" [ 16 ]
Sampler "independent" "integer pixelsamples" [ 256 ]
Integrator "path" "integer maxdepth" [ %d ]
WorldBegin
Material "diffuse" "rgb reflectance" [ %g %g %g ]
AreaLightSource "diffuse" "rgb L" [ 1 1 1 ] "bool twosided" true
Shape "sphere" "float radius" [ 10 ]
)", max_depth, rho, rho, rho);
  return load_pbrt_string(buf, "<furnace>", ".");
}

SceneDesc shipped(const char* name, int w, int h, int spp, int max_depth) {
  SceneDesc d = load_pbrt_file(testing::source_dir() + "/scenes/" + name + ".pbrt");
  d.film.xres = w;
  d.film.yres = h;
  d.spp = spp;
  d.max_depth = max_depth;
  return d;
}

TEST(GuidedFurnace, ClosedSphereMatchesTheAnalyticValue) {
  // L = Le * sum_{k=0..5} 0.5^k with pbrt's depth counting.
  const double expected = 1.96875;
  GuidedSetup s(furnace(0.5, 5));
  for (GuideTarget target : {GuideTarget::ExpectedSarsa, GuideTarget::QLearning}) {
    for (bool nee : {true, false}) {
      GuideField guide = s.make_guide(target);
      RenderOptions opt;
      opt.nee = nee;
      RenderResult r = s.run(&guide, opt);
      MeanAndError m = image_mean_and_error(r.film);
      EXPECT_NEAR(m.mean, expected, 0.01 * expected) << "nee " << nee;
      EXPECT_GT(r.stats.counters.path.guided_samples, 0u);
      EXPECT_GT(r.stats.guide.updates, 0u);
      EXPECT_EQ(r.stats.counters.rejected_nonfinite, 0u);
      EXPECT_EQ(r.stats.guide.rejected_nonfinite, 0u);
    }
  }
}

// The hard scenes: guided means agree with unguided ones.
TEST(GuidedUnbiased, DoorAjarAndShelterAgreeWithUnguided) {
  for (const char* name : {"door-ajar", "shelter"}) {
    SCOPED_TRACE(name);
    GuidedSetup s(shipped(name, 40, 30, 192, 8));
    GuideField guide = s.make_guide();
    RenderResult g = s.run(&guide);
    RenderResult u = s.run(nullptr);
    MeanAndError mg = image_mean_and_error(g.film), mu = image_mean_and_error(u.film);
    ASSERT_GT(mu.mean, 0.0);
    ASSERT_LT(mu.se, 0.05 * mu.mean) << "test too noisy to mean anything";
    expect_agree(mg, mu);
    EXPECT_TRUE(all_finite(g.film));
    EXPECT_GT(g.stats.guide.splits, 0u) << "the field never refined";
  }
}

// Rough conductors and a coated surface are guided too (the share fades with
// roughness); the mixture pdf must stay right for their lobes.
TEST(GuidedUnbiased, GlossyMaterialsAgreeWithUnguided) {
  const char* scene = R"(
LookAt 0 1 -2.5  0 1 0  0 1 0
Camera "perspective" "float fov" [ 60 ]
Film "rgb" "integer xresolution" [ 32 ] "integer yresolution" [ 32 ]
Sampler "independent" "integer pixelsamples" [ 256 ]
Integrator "path" "integer maxdepth" [ 6 ]
WorldBegin
Material "conductor" "float roughness" [ 0.3 ] "rgb reflectance" [ 0.8 0.7 0.5 ]
Shape "trianglemesh" "point3 P" [ -1 0 -3  1 0 -3  1 2 -3  -1 2 -3  -1 0 1  1 0 1  1 2 1  -1 2 1 ]
  "integer indices" [ 0 1 2 0 2 3  4 6 5 4 7 6  0 4 5 0 5 1  3 2 6 3 6 7 ]
Material "coateddiffuse" "float roughness" [ 0.2 ] "rgb reflectance" [ 0.5 0.6 0.7 ]
Shape "trianglemesh" "point3 P" [ -1 0 -3  -1 2 -3  -1 2 1  -1 0 1  1 0 -3  1 2 -3  1 2 1  1 0 1 ]
  "integer indices" [ 0 1 2 0 2 3  4 6 5 4 7 6 ]
Material "conductor" "float roughness" [ 0.1 ]
Shape "sphere" "float radius" [ 0.35 ]
AttributeBegin
  AreaLightSource "diffuse" "rgb L" [ 8 8 8 ]
  Shape "trianglemesh" "point3 P" [ -0.3 1.99 -0.3  0.3 1.99 -0.3  0.3 1.99 0.3  -0.3 1.99 0.3 ]
    "integer indices" [ 0 1 2 0 2 3 ]
AttributeEnd
)";
  GuidedSetup s(load_pbrt_string(scene, "<glossy-box>", "."));
  GuideField guide = s.make_guide();
  RenderResult g = s.run(&guide);
  RenderResult u = s.run(nullptr);
  EXPECT_GT(g.stats.counters.path.guided_samples, 0u);
  MeanAndError mu = image_mean_and_error(u.film);
  ASSERT_GT(mu.mean, 0.0);
  expect_agree(image_mean_and_error(g.film), mu);
}

TEST(GuidedDeterminism, BitIdenticalImageAndCacheAcrossThreadCounts) {
  GuidedSetup s(shipped("shelter", 32, 24, 12, 6));
  RenderResult results[3];
  GuideField guides[3] = {s.make_guide(), s.make_guide(), s.make_guide()};
  const int threads[3] = {1, 2, 4}, tiles[3] = {16, 8, 5};
  for (int i = 0; i < 3; ++i) {
    RenderOptions opt;
    opt.threads = threads[i];
    opt.tile_size = tiles[i];
    opt.seed = 7;
    results[i] = s.run(&guides[i], opt);
  }
  EXPECT_TRUE(films_identical(results[0].film, results[1].film));
  EXPECT_TRUE(films_identical(results[0].film, results[2].film));
  EXPECT_TRUE(guides[0] == guides[1]);
  EXPECT_TRUE(guides[0] == guides[2]);
  EXPECT_GT(guides[0].num_cells(), 6u);
}

TEST(GuidedCacheRoundTrip, SavedCacheRendersTheSameImage) {
  GuidedSetup s(shipped("door-ajar", 24, 18, 8, 6));
  GuideField guide = s.make_guide();
  s.run(&guide);
  std::stringstream bytes;
  guide.save(bytes, s.scene.fingerprint());
  GuideField loaded = GuideField::load(bytes, s.scene.fingerprint());
  ASSERT_TRUE(loaded == guide);
  GuideField copy = guide;
  RenderResult a = s.run(&copy), b = s.run(&loaded);
  EXPECT_TRUE(films_identical(a.film, b.film));
  EXPECT_TRUE(copy == loaded);
}

// A field with one enormous bin in every cell: sampling is extremely peaked,
// yet the mixture keeps the estimate finite and unbiased.
TEST(GuideDegenerate, HugeBinEverywhereStaysFiniteAndUnbiased) {
  SceneDesc d = load_builtin_cornell_box();
  d.film.xres = 32;
  d.film.yres = 32;
  d.spp = 96;
  GuidedSetup s(std::move(d));
  GuideField guide = s.make_guide();
  {
    GuideView g = guide.view();
    const Float huge = 1e5f * s.scene.max_emitted_radiance();
    for (uint32_t c = 0; c < guide.num_cells(); ++c) ASSERT_TRUE(guide_record(g, int32_t(c), 17, huge));
    guide.fold();
  }
  RenderResult g = s.run(&guide);
  RenderResult u = s.run(nullptr);
  EXPECT_EQ(g.stats.counters.rejected_nonfinite, 0u);
  EXPECT_TRUE(all_finite(g.film));
  expect_agree(image_mean_and_error(g.film), image_mean_and_error(u.film));
}

TEST(GuideDegenerate, InjectedNonFiniteTargetsAreRejectedAndCounted) {
  SceneDesc d = load_builtin_cornell_box();
  d.film.xres = 16;
  d.film.yres = 16;
  d.spp = 4;
  GuidedSetup s(std::move(d));
  GuideField guide = s.make_guide();
  {
    GuideView g = guide.view();
    EXPECT_FALSE(guide_record(g, 0, 3, std::nanf("")));
    EXPECT_FALSE(guide_record(g, 0, 3, INFINITY));
    EXPECT_FALSE(guide_record(g, 0, 3, -INFINITY));
  }
  RenderResult r = s.run(&guide);
  EXPECT_EQ(r.stats.guide.rejected_nonfinite, 3u);
  EXPECT_TRUE(all_finite(r.film));
  for (uint32_t c = 0; c < guide.num_cells(); ++c)
    for (uint32_t j = 0; j < 144; ++j) ASSERT_TRUE(std::isfinite(guide.cell_values(int32_t(c))[j]));
}

// A tiny light in a closed box: almost every learned target is zero, the
// few that are not are large.
TEST(GuideDegenerate, TinyLightStaysFiniteAndUnbiased) {
  const char* scene = R"(
LookAt 0 1 -2.5  0 1 0  0 1 0
Camera "perspective" "float fov" [ 60 ]
Film "rgb" "integer xresolution" [ 32 ] "integer yresolution" [ 32 ]
Sampler "independent" "integer pixelsamples" [ 128 ]
Integrator "path" "integer maxdepth" [ 6 ]
WorldBegin
Material "diffuse" "rgb reflectance" [ 0.7 0.7 0.7 ]
Shape "trianglemesh" "point3 P" [ -1 0 -3  1 0 -3  1 2 -3  -1 2 -3  -1 0 1  1 0 1  1 2 1  -1 2 1 ]
  "integer indices" [ 0 1 2 0 2 3  4 6 5 4 7 6  0 4 5 0 5 1  3 2 6 3 6 7  0 3 7 0 7 4  1 5 6 1 6 2 ]
AttributeBegin
  AreaLightSource "diffuse" "rgb L" [ 40000 40000 40000 ]
  Shape "trianglemesh" "point3 P" [ -0.005 1.99 -0.005  0.005 1.99 -0.005  0.005 1.99 0.005  -0.005 1.99 0.005 ]
    "integer indices" [ 0 1 2 0 2 3 ]
AttributeEnd
)";
  GuidedSetup s(load_pbrt_string(scene, "<tiny-light>", "."));
  GuideField guide = s.make_guide();
  RenderResult g = s.run(&guide);
  RenderResult u = s.run(nullptr);
  EXPECT_EQ(g.stats.counters.rejected_nonfinite, 0u);
  EXPECT_EQ(g.stats.guide.rejected_nonfinite + g.stats.guide.rejected_large, 0u);
  EXPECT_TRUE(all_finite(g.film));
  MeanAndError mu = image_mean_and_error(u.film);
  ASSERT_GT(mu.mean, 0.0);
  expect_agree(image_mean_and_error(g.film), mu);
}

}  // namespace
}  // namespace tessera
