// Guided rendering end to end, complementing guided_render_test.cpp:
//  - analytic furnaces with learned light selection switched on, mostly
//    guided sampling, non-default field settings (odd and fine grids, no
//    floor, eager splits against a small memory budget), and under an
//    environment light;
//  - agreement with unguided renders, per channel and with independent seeds,
//    on scenes whose guided vertices are glossy, coated or refractive, and
//    with the Q-learning rule on the hard scenes;
//  - bit-identical films and fields across threads and tiles on such a scene;
//  - degenerate fields (one huge bin everywhere, even with pure guided
//    sampling; every kind of rejected target; several tiny lights);
//  - a refined cache with learned light entries round-tripping through
//    save/load;
//  - learning visibly working: fewer zero-contribution paths.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "guided_helpers.h"
#include "scene/builtin_scenes.h"

namespace tessera {
namespace {

using namespace tessera::testing;

// What every guided render must show: guiding ran (unless nothing was there
// to learn) and learned, and no estimate or target was NaN, infinite or negative.
void expect_clean_guided_run(const RenderResult& r, const std::string& what, bool expect_guided_samples = true) {
  if (expect_guided_samples) {
    EXPECT_GT(r.stats.counters.path.guided_samples, 0u) << what;
  }
  EXPECT_GT(r.stats.counters.path.guide_updates, 0u) << what;
  EXPECT_GT(r.stats.guide.updates, 0u) << what;
  EXPECT_EQ(r.stats.counters.rejected_nonfinite, 0u) << what;
  EXPECT_EQ(r.stats.counters.rejected_negative, 0u) << what;
  EXPECT_EQ(r.stats.guide.rejected_nonfinite, 0u) << what;
  EXPECT_EQ(r.stats.guide.rejected_large, 0u) << what;
  EXPECT_TRUE(all_finite(r.film)) << what;
}


// L = Le * sum_{k=0..D} rho^k inside any closed emitter of uniform Le and
// albedo rho (pbrt's depth counting).
double furnace_value(double rho, int depth) {
  double s = 0, r = 1;
  for (int k = 0; k <= depth; ++k, r *= rho) s += r;
  return s;
}

// A furnace's mean, per channel, against its analytic value. Ordinary
// settings must land within 1% (rel_tol); the test first checks its own
// precision: a standard error below 0.3% makes 1% at least 3.3 standard
// errors. Settings that sample mostly from the guide are much noisier (the
// piecewise-constant Q x cos of 144 bins over the sphere is a poor fit to a
// cosine lobe near the horizon), so there rel_tol = 0 asks for 4 standard
// errors instead, with max_rel_se bounding how loose that may get.
void expect_furnace(const RenderResult& r, double expected, double rel_tol, double max_rel_se,
                    const std::string& what) {
  const ChannelStats s = channel_stats(r.film);
  for (int c = 0; c < 3; ++c) {
    EXPECT_LT(s.se[c], max_rel_se * expected) << what << ": too noisy to test, channel " << c;
    const double tol = rel_tol > 0 ? rel_tol * expected : 4.0 * s.se[c];
    EXPECT_NEAR(s.mean[c], expected, tol) << what << ", channel " << c << ", standard error " << s.se[c];
  }
  expect_clean_guided_run(r, what);
}

std::string sphere_furnace(double rho, int max_depth) {
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
)",
                max_depth, rho, rho, rho);
  return buf;
}

// A closed emitting cube seen from inside: 12 emitting triangles, so the
// guide learns light selection too (a sphere has far more triangles than
// GuideConfig::max_learned_lights).
std::string cube_furnace(double rho, int max_depth) {
  char buf[1536];
  std::snprintf(buf, sizeof buf, R"(
LookAt 0.1 -0.2 0.05  1 0.3 0.6  0 1 0
Camera "perspective" "float fov" [ 70 ]
Film "rgb" "integer xresolution" [ 16 ] "integer yresolution" [ 16 ]
Sampler "independent" "integer pixelsamples" [ 256 ]
Integrator "path" "integer maxdepth" [ %d ]
WorldBegin
Material "diffuse" "rgb reflectance" [ %g %g %g ]
AreaLightSource "diffuse" "rgb L" [ 1 1 1 ] "bool twosided" true
Shape "trianglemesh" "point3 P" [ -1 -1 -1  1 -1 -1  1 1 -1  -1 1 -1  -1 -1 1  1 -1 1  1 1 1  -1 1 1 ]
  "integer indices" [ 0 1 2 0 2 3  4 6 5 4 7 6  0 4 5 0 5 1  3 2 6 3 6 7  0 3 7 0 7 4  1 5 6 1 6 2 ]
)",
                max_depth, rho, rho, rho);
  return buf;
}

using testing::rule_name;

// --- Furnaces -----------------------------------------------------------------

TEST(GuidedFurnace, EmittingCubeWithLearnedLightSelection) {
  const double expected = furnace_value(0.5, 5);
  GuidedScene s(load_pbrt_string(cube_furnace(0.5, 5), "<cube-furnace>", "."));
  ASSERT_EQ(s.scene.view().num_lights, 12u);
  for (GuideTarget target : {GuideTarget::ExpectedSarsa, GuideTarget::QLearning}) {
    for (bool nee : {true, false}) {
      const std::string what = std::string(rule_name(target)) + (nee ? " with NEE" : " without NEE");
      GuideField guide = s.make_guide(config_with(target));
      ASSERT_EQ(guide.learned_lights(), 12u);
      RenderOptions opt;
      opt.nee = nee;
      RenderResult r = s.run(&guide, opt);
      expect_furnace(r, expected, 0.01, 0.003, what);
      EXPECT_EQ(r.stats.guide_mode, rule_name(target));
      EXPECT_GT(r.stats.guide.splits, 0u) << what;
    }
  }
}

// Mostly guided directions (mixture weight 0.8) on a coarse, odd grid whose
// bins straddle the faces' horizons. Flat faces give every cell its exact
// normal, the best case for the guide's cosine factor. Heavier guiding is
// unbiased too but heavy-tailed: the cosine is taken at bin centres, so bins
// straddling the horizon get little more than the floor and single paths
// carry weights of ~10 per bounce. Over 60 seeds the standard error here was
// at most 0.30% at weight 0.8 and 0.50% at 0.9; at weight 1 and 1024 spp it
// varied 40x between seeds.
TEST(GuidedFurnace, EmittingCubeSampledMostlyFromTheGuide) {
  const double expected = furnace_value(0.5, 5);
  GuidedScene s(load_pbrt_string(cube_furnace(0.5, 5), "<cube-furnace>", "."));
  for (bool nee : {true, false}) {
    const std::string what = std::string("mixture 0.8") + (nee ? " with NEE" : " without NEE");
    GuideConfig cfg = config_with(GuideTarget::ExpectedSarsa, 0.8f);
    cfg.grid = 5;
    GuideField guide = s.make_guide(cfg);
    RenderOptions opt;
    opt.nee = nee;
    RenderResult r = s.run(&guide, opt);
    expect_furnace(r, expected, 0.0, 0.005, what);
  }
}

// Settings that change how the field is stored and learned, never what is
// estimated. A sphere: its cells' mean normals are only approximate.
TEST(GuidedFurnace, SphereWithNonDefaultFieldSettings) {
  const double expected = furnace_value(0.5, 5);
  GuidedScene s(load_pbrt_string(sphere_furnace(0.5, 5), "<sphere-furnace>", "."));
  struct Case {
    const char* name;
    GuideConfig cfg;
  };
  std::vector<Case> cases(3);
  cases[0].name = "grid 5";
  cases[0].cfg.grid = 5;
  cases[1].name = "grid 32, no floor";
  cases[1].cfg.grid = 32;
  cases[1].cfg.floor = 0.f;
  cases[2].name = "eager splits, budget of 20 cells, q-learning";
  cases[2].cfg.split_updates = 64;
  cases[2].cfg.target = GuideTarget::QLearning;
  // A fresh field has 6 cells (one per normal class); each split adds 7.
  cases[2].cfg.budget_bytes = s.make_guide(cases[2].cfg).stats().bytes / 6 * 20;
  for (const Case& c : cases) {
    for (bool nee : {true, false}) {
      const std::string what = std::string(c.name) + (nee ? " with NEE" : " without NEE");
      GuideField guide = s.make_guide(c.cfg);
      RenderOptions opt;
      opt.nee = nee;
      opt.guide_learn.all_spp = UINT32_MAX;  // these field settings learn from every sample
      RenderResult r = s.run(&guide, opt);
      expect_furnace(r, expected, 0.01, 0.003, what);
      if (c.cfg.split_updates == 64) {
        EXPECT_GT(r.stats.guide.splits, 0u) << what;
        EXPECT_TRUE(r.stats.guide.budget_reached) << what;
        EXPECT_LE(r.stats.guide.bytes, c.cfg.budget_bytes) << what;
      }
    }
  }
}

// A diffuse convex sphere under a uniform environment L = 1 never sees itself:
// it reflects exactly rho, and the background is exactly 1. Guiding learns
// from escaping rays here (the environment targets).
TEST(GuidedFurnace, ConvexSphereUnderUniformEnvironment) {
  const char* scene = R"(
LookAt 0 0 -5  0 0 0  0 1 0
Camera "perspective" "float fov" [ 20 ]
Film "rgb" "integer xresolution" [ 32 ] "integer yresolution" [ 32 ]
Sampler "independent" "integer pixelsamples" [ 128 ]
Integrator "path" "integer maxdepth" [ 5 ]
WorldBegin
LightSource "infinite" "rgb L" [ 1 1 1 ]
Material "diffuse" "rgb reflectance" [ 0.6 0.6 0.6 ]
Shape "sphere" "float radius" [ 1 ]
)";
  GuidedScene s(load_pbrt_string(scene, "<env-sphere>", "."));
  for (GuideTarget target : {GuideTarget::ExpectedSarsa, GuideTarget::QLearning}) {
    for (bool nee : {true, false}) {
      const std::string what = std::string(rule_name(target)) + (nee ? " with NEE" : " without NEE");
      GuideField guide = s.make_guide(config_with(target));
      RenderOptions opt;
      opt.nee = nee;
      RenderResult r = s.run(&guide, opt);
      // With NEE the environment is NEE's to deliver and the sphere never
      // sees itself: every target is 0, no cell learns any light, and a cell
      // that has learned nothing samples the BSDF only.
      expect_clean_guided_run(r, what, !nee);
      if (nee) {
        EXPECT_EQ(r.stats.counters.path.guided_samples, 0u) << what;
      }
      const ImageRgb img = film_mean(r.film), var = film_variance_of_mean(r.film);
      // The central 8x8 pixels lie on the sphere (it spans ~ +-0.2 rad of the
      // 0.35 rad field of view). Their mean must be rho within 4 standard
      // errors; guiding makes this scene noisier than cosine sampling (which
      // is exact here without NEE), but the error stays below 1% of rho.
      for (int c = 0; c < 3; ++c) {
        double centre = 0, v = 0;
        for (int y = 12; y < 20; ++y)
          for (int x = 12; x < 20; ++x) {
            centre += img.rgb[3 * (y * 32 + x) + c];
            v += var.rgb[3 * (y * 32 + x) + c];
          }
        const double se = std::sqrt(v) / 64;
        EXPECT_LT(se, 0.006) << what << ", channel " << c;
        EXPECT_NEAR(centre / 64, 0.6, 4 * se) << what << ", channel " << c;
        EXPECT_NEAR(img.rgb[c], 1.0, 1e-5) << what << ": background, channel " << c;
      }
    }
  }
}

// --- Agreement with unguided renders ---------------------------------------------


// Glossy: rough conductors and a rough dielectric are guided (bin-sampled
// learning targets, guided transmission), the smooth glass sphere exercises
// the delta-vertex targets. Pillars: dark absorbing walls, one light.
TEST(GuidedUnbiased, GlossyAndPillarsAgreeWithUnguided) {
  for (const char* name : {"glossy", "pillars"}) {
    GuidedScene s(shipped(name, 40, 30, 64, 8));
    GuideField guide = s.make_guide();
    RenderResult g = s.run(&guide, seeded(1)), u = s.run(nullptr, seeded(2));
    const ChannelStats mg = channel_stats(g.film), mu = channel_stats(u.film);
    expect_precise(mu, 0.03, name);
    expect_agree(mg, mu, name);
    expect_clean_guided_run(g, name);
    EXPECT_GT(g.stats.guide.splits, 0u) << name << ": the field never refined";
  }
}

// Every guided non-Lambertian lobe filling a large part of the image: rough
// conductor floor and right wall, a rough coated-diffuse left wall and a
// rough glass sphere (guided transmission), all rough enough to be guided at
// the full mixture weight. A mixture pdf that is wrong for one BSDF type
// shifts that region by several percent; the standard errors here are ~0.3%.
TEST(GuidedUnbiased, RoughMaterialsBoxAgreesWithUnguided) {
  const char* scene = R"(
LookAt 0 1 -2.5  0 0.8 0  0 1 0
Camera "perspective" "float fov" [ 65 ]
Film "rgb" "integer xresolution" [ 32 ] "integer yresolution" [ 24 ]
Sampler "independent" "integer pixelsamples" [ 192 ]
Integrator "path" "integer maxdepth" [ 6 ]
WorldBegin
Material "diffuse" "rgb reflectance" [ 0.7 0.7 0.7 ]
Shape "trianglemesh" "point3 P" [ -1 2 -3  1 2 -3  1 2 1  -1 2 1  -1 0 1  1 0 1  1 2 1  -1 2 1  -1 0 -3  1 0 -3  1 2 -3  -1 2 -3 ]
  "integer indices" [ 0 1 2 0 2 3  4 5 6 4 6 7  8 9 10 8 10 11 ]
Material "conductor" "float roughness" [ 0.3 ] "rgb reflectance" [ 0.9 0.8 0.6 ]
Shape "trianglemesh" "point3 P" [ -1 0 -3  1 0 -3  1 0 1  -1 0 1 ] "integer indices" [ 0 1 2 0 2 3 ]
Material "conductor" "float roughness" [ 0.15 ] "rgb reflectance" [ 0.6 0.8 0.9 ]
Shape "trianglemesh" "point3 P" [ 1 0 -3  1 2 -3  1 2 1  1 0 1 ] "integer indices" [ 0 1 2 0 2 3 ]
Material "coateddiffuse" "float roughness" [ 0.3 ] "rgb reflectance" [ 0.3 0.5 0.7 ]
Shape "trianglemesh" "point3 P" [ -1 0 -3  -1 2 -3  -1 2 1  -1 0 1 ] "integer indices" [ 0 1 2 0 2 3 ]
AttributeBegin
  Material "dielectric" "float eta" [ 1.5 ] "float roughness" [ 0.3 ]
  Translate 0 0.55 -0.2
  Shape "sphere" "float radius" [ 0.5 ]
AttributeEnd
AttributeBegin
  AreaLightSource "diffuse" "rgb L" [ 10 10 10 ]
  Shape "trianglemesh" "point3 P" [ -0.3 1.99 -1.6  0.3 1.99 -1.6  0.3 1.99 -1  -0.3 1.99 -1 ]
    "integer indices" [ 0 1 2 0 2 3 ]
AttributeEnd
)";
  GuidedScene s(load_pbrt_string(scene, "<rough-materials>", "."));
  const ChannelStats mu = channel_stats(s.run(nullptr, seeded(1)).film);
  expect_precise(mu, 0.005, "unguided");
  GuideField guide = s.make_guide();
  RenderResult g = s.run(&guide, seeded(2));
  expect_agree(channel_stats(g.film), mu, "qtable");
  expect_clean_guided_run(g, "qtable");
  // Most vertices are guidable: the lobes are rough enough for the full weight.
  EXPECT_GT(g.stats.counters.path.guided_samples, g.stats.counters.path.guidable_vertices / 3);
}

// The hard scenes with both learning rules: the light is hidden (door-ajar),
// or each light has its own blocker and the guide also learns light
// selection (shelter, 3 quads = 6 lights).
// Slow-ish (door-ajar at 512 spp, three times; a ctest test of its own):
// the spp buys the 3% standard error that expect_precise asks for.
TEST(GuidedUnbiased, DoorAjarAndShelterAgreeWithUnguidedForBothRules) {
  struct Case {
    const char* name;
    int spp;
  };
  // door-ajar is dark and noisy (~97% of paths carry nothing at depth 8): it
  // needs ~5x the samples of shelter for a 3% standard error.
  for (const Case& c : {Case{"door-ajar", 512}, Case{"shelter", 96}}) {
    GuidedScene s(shipped(c.name, 40, 30, c.spp, 8));
    const ChannelStats mu = channel_stats(s.run(nullptr, seeded(1)).film);
    expect_precise(mu, 0.03, c.name);
    for (GuideTarget target : {GuideTarget::ExpectedSarsa, GuideTarget::QLearning}) {
      const std::string what = std::string(c.name) + " " + rule_name(target);
      GuideField guide = s.make_guide(config_with(target));
      RenderResult g = s.run(&guide, seeded(target == GuideTarget::QLearning ? 3 : 2));
      expect_agree(channel_stats(g.film), mu, what);
      expect_clean_guided_run(g, what);
      if (std::string(c.name) == "shelter") {
        EXPECT_EQ(guide.learned_lights(), 6u) << what;
      }
    }
  }
}

// --- Determinism --------------------------------------------------------------

TEST(GuidedDeterminism, GlossySceneBitIdenticalAcrossThreadsAndTiles) {
  GuidedScene s(shipped("glossy", 32, 24, 12, 8));
  const int threads[3] = {1, 2, 4}, tiles[3] = {16, 7, 5};
  RenderResult results[3];
  GuideField guides[3] = {s.make_guide(), s.make_guide(), s.make_guide()};
  for (int i = 0; i < 3; ++i) {
    RenderOptions opt;
    opt.threads = threads[i];
    opt.tile_size = tiles[i];
    opt.seed = 11;
    results[i] = s.run(&guides[i], opt);
  }
  for (int i = 1; i < 3; ++i) {
    SCOPED_TRACE(threads[i]);
    EXPECT_TRUE(films_identical(results[0].film, results[i].film));
    EXPECT_TRUE(guides[0] == guides[i]);
    EXPECT_EQ(results[0].stats.counters.path.guide_updates, results[i].stats.counters.path.guide_updates);
    EXPECT_EQ(results[0].stats.counters.path.guided_samples, results[i].stats.counters.path.guided_samples);
    EXPECT_EQ(results[0].stats.guide.splits, results[i].stats.guide.splits);
  }
  EXPECT_GT(guides[0].num_cells(), 6u) << "the field never refined: equality of fields says little";

  // The comparisons can fail: another seed learns another field.
  RenderOptions other;
  other.threads = 2;
  other.seed = 12;
  GuideField g2 = s.make_guide();
  RenderResult r2 = s.run(&g2, other);
  EXPECT_FALSE(films_identical(results[0].film, r2.film));
  EXPECT_FALSE(guides[0] == g2);
}

// --- Degenerate fields --------------------------------------------------------

// Gives every cell one enormous bin (1e5 times the brightest emitter,
// inside the accepted range of targets) and folds it in.
void inject_huge_bin(GuidedScene& s, GuideField& guide, uint32_t bin) {
  GuideView g = guide.view();
  const Float huge = 1e5f * s.scene.max_emitted_radiance();
  for (uint32_t c = 0; c < guide.num_cells(); ++c) ASSERT_TRUE(guide_record(g, static_cast<int32_t>(c), bin, huge));
  guide.fold();
  EXPECT_EQ(guide.stats().rejected_large, 0u);
}

// Sampling is as peaked as it gets, and with a mixture of 1 only the floor
// reaches the directions that matter: the weights grow large but stay finite,
// and the mean stays the unguided one. Those weights make the estimate
// heavy-tailed, so the normal approximation behind the 4-sigma comparison
// needs many samples: at 512 spp one of the six cases missed it by chance,
// with and without guided roulette alike, and agreed again at 2048.
// Slow on purpose (7 renders at 2048 spp, ~10 s on an idle core; a ctest
// test of its own): the spp is what the heavy tail needs, as said above.
TEST(GuideDegenerate, HugeBinWithPureGuidedSamplingStaysFiniteAndUnbiased) {
  SceneDesc d = load_builtin_cornell_box();
  d.film.xres = 32;
  d.film.yres = 24;
  d.spp = 2048;
  d.max_depth = 6;
  GuidedScene s(std::move(d));
  const ChannelStats mu = channel_stats(s.run(nullptr, seeded(1)).film);
  expect_precise(mu, 0.03, "unguided");
  uint64_t seed = 2;
  for (Float prob : {0.5f, 1.0f}) {
    // Bin 0 and the last bin point to opposite corners of the octahedral map:
    // whichever normal class a cell has, the huge bin faces it in some cells
    // and faces away (zero cosine weight) in others.
    for (uint32_t bin : {0u, 143u, 77u}) {
      const std::string what = "mixture " + std::to_string(prob) + ", bin " + std::to_string(bin);
      GuideField guide = s.make_guide(config_with(GuideTarget::ExpectedSarsa, prob));
      inject_huge_bin(s, guide, bin);
      RenderResult g = s.run(&guide, seeded(seed++));
      EXPECT_EQ(g.stats.counters.rejected_nonfinite, 0u) << what;
      EXPECT_EQ(g.stats.counters.rejected_negative, 0u) << what;
      EXPECT_TRUE(all_finite(g.film)) << what;
      const ChannelStats mg = channel_stats(g.film);
      expect_agree(mg, mu, what);
    }
  }
}

// Every kind of bad target is refused before it reaches the field, counted
// in the right place, and leaves the field exactly as it was.
TEST(GuideDegenerate, RejectedTargetsLeaveTheFieldUntouched) {
  SceneDesc d = load_builtin_cornell_box();
  d.film.xres = 16;
  d.film.yres = 16;
  d.spp = 8;
  GuidedScene s(std::move(d));
  GuideField guide = s.make_guide();
  const GuideField fresh = guide;
  {
    GuideView g = guide.view();
    const int32_t cell = guide.find_cell(Vec3(278.f, 0.f, 278.f), Vec3(0.f, 1.f, 0.f));  // the floor
    ASSERT_GE(cell, 0);
    EXPECT_FALSE(guide_record(g, cell, 3, std::nanf("")));
    EXPECT_FALSE(guide_record(g, cell, 3, INFINITY));
    EXPECT_FALSE(guide_record(g, cell, 3, -INFINITY));
    EXPECT_FALSE(guide_record(g, cell, 3, -1.f));
    EXPECT_FALSE(guide_record(g, cell, 3, -1e-30f));
    // Finite but beyond the fixed-point range (2^20 x the brightest emitter).
    EXPECT_FALSE(guide_record(g, cell, 3, 2e6f * s.scene.max_emitted_radiance()));
    EXPECT_FALSE(guide_record(g, cell, 3, 3e38f));
    EXPECT_TRUE(guide_record(g, cell, 3, 0.f)) << "zero is a valid target";
  }
  guide.fold();
  EXPECT_EQ(guide.stats().rejected_nonfinite, 5u);
  EXPECT_EQ(guide.stats().rejected_large, 2u);
  EXPECT_EQ(guide.stats().updates, 1u);
  const uint32_t entries = guide.view().stride;
  for (uint32_t c = 0; c < guide.num_cells(); ++c)
    for (uint32_t j = 0; j < entries; ++j) ASSERT_EQ(guide.cell_values(static_cast<int32_t>(c))[j], 0.f);

  // Rendering afterwards works and adds no rejections of its own.
  RenderResult r = s.run(&guide);
  EXPECT_EQ(r.stats.guide.rejected_nonfinite, 5u);
  EXPECT_EQ(r.stats.guide.rejected_large, 2u);
  EXPECT_EQ(r.stats.counters.rejected_nonfinite, 0u);
  EXPECT_TRUE(all_finite(r.film));
  EXPECT_GT(r.stats.guide.updates, 1u);
  EXPECT_FALSE(guide == fresh) << "the render did not learn";
}

// Three tiny, very bright lights in a closed box (6 emitting triangles, so
// light selection is learned too): almost every target is zero, the few that
// are not are large. The lights are out of the camera's view: a camera ray
// that hits one by chance would carry L = 40000 on its own.
TEST(GuideDegenerate, SeveralTinyLightsStayFiniteAndUnbiased) {
  const char* scene = R"(
LookAt 0 1 -2.5  0 1 0  0 1 0
Camera "perspective" "float fov" [ 60 ]
Film "rgb" "integer xresolution" [ 32 ] "integer yresolution" [ 24 ]
Sampler "independent" "integer pixelsamples" [ 128 ]
Integrator "path" "integer maxdepth" [ 6 ]
WorldBegin
Material "diffuse" "rgb reflectance" [ 0.7 0.6 0.5 ]
Shape "trianglemesh" "point3 P" [ -1 0 -3  1 0 -3  1 2 -3  -1 2 -3  -1 0 1  1 0 1  1 2 1  -1 2 1 ]
  "integer indices" [ 0 1 2 0 2 3  4 6 5 4 7 6  0 4 5 0 5 1  3 2 6 3 6 7  0 3 7 0 7 4  1 5 6 1 6 2 ]
AttributeBegin
  AreaLightSource "diffuse" "rgb L" [ 40000 40000 40000 ]
  Shape "trianglemesh" "point3 P" [ -0.705 1.99 -2.805  -0.695 1.99 -2.805  -0.695 1.99 -2.795  -0.705 1.99 -2.795 ]
    "integer indices" [ 0 1 2 0 2 3 ]
AttributeEnd
AttributeBegin
  AreaLightSource "diffuse" "rgb L" [ 20000 20000 20000 ]
  Shape "trianglemesh" "point3 P" [ 0.695 0.01 -2.805  0.705 0.01 -2.805  0.705 0.01 -2.795  0.695 0.01 -2.795 ]
    "integer indices" [ 0 2 1 0 3 2 ]
AttributeEnd
AttributeBegin
  AreaLightSource "diffuse" "rgb L" [ 40000 40000 40000 ]
  Shape "trianglemesh" "point3 P" [ 0.99 1.5 -2.005  0.99 1.51 -2.005  0.99 1.51 -1.995  0.99 1.5 -1.995 ]
    "integer indices" [ 0 2 1 0 3 2 ]
AttributeEnd
)";
  GuidedScene s(load_pbrt_string(scene, "<tiny-lights>", "."));
  const SceneView& v = s.scene.view();
  ASSERT_EQ(v.num_lights, 6u);
  // One-sided emitters 1 cm from a wall must face the room, not the wall.
  for (uint32_t l = 0; l < v.num_lights; ++l) {
    const Vec3 p = s.scene.positions()[s.scene.indices()[3 * v.lights[l].triangle]] + Vec3(s.scene.desc().render_origin);
    EXPECT_GT(glm::dot(v.face_normals[v.lights[l].triangle], Vec3(0.f, 1.f, -1.f) - p), 0.f) << "light " << l;
  }
  const ChannelStats mu = channel_stats(s.run(nullptr, seeded(1)).film);
  expect_precise(mu, 0.03, "unguided");
  for (GuideTarget target : {GuideTarget::ExpectedSarsa, GuideTarget::QLearning}) {
    const std::string what = rule_name(target);
    GuideField guide = s.make_guide(config_with(target));
    ASSERT_EQ(guide.learned_lights(), 6u);
    RenderResult g = s.run(&guide, seeded(target == GuideTarget::QLearning ? 3 : 2));
    expect_clean_guided_run(g, what);
    expect_agree(channel_stats(g.film), mu, what);
  }
}

// --- Serialisation ------------------------------------------------------------

TEST(GuidedCacheRoundTrip, RefinedCacheWithLearnedLightsRendersTheSameImage) {
  GuidedScene s(shipped("shelter", 32, 24, 16, 6));
  GuideField guide = s.make_guide();
  s.run(&guide);
  ASSERT_GT(guide.learned_lights(), 0u);
  ASSERT_GT(guide.num_cells(), 6u) << "nothing refined: the round trip would test little";

  std::stringstream bytes;
  guide.save(bytes, s.scene.fingerprint());
  const std::string saved = bytes.str();
  GuideField loaded = GuideField::load(bytes, s.scene.fingerprint());
  ASSERT_TRUE(loaded == guide);
  EXPECT_EQ(loaded.learned_lights(), guide.learned_lights());
  EXPECT_EQ(loaded.stats().updates, guide.stats().updates);
  EXPECT_EQ(loaded.stats().splits, guide.stats().splits);
  std::stringstream again;
  loaded.save(again, s.scene.fingerprint());
  EXPECT_EQ(again.str(), saved) << "save(load(x)) differs from x";

  // The same state renders the same image and learns the same field.
  GuideField copy = guide;
  RenderOptions opt;
  opt.seed = 3;
  RenderResult a = s.run(&copy, opt), b = s.run(&loaded, opt);
  EXPECT_TRUE(films_identical(a.film, b.film));
  EXPECT_TRUE(copy == loaded);
  EXPECT_FALSE(copy == guide) << "the second render did not learn";

  // Another scene's fingerprint, or a damaged stream, is refused.
  std::stringstream other(saved);
  EXPECT_THROW(GuideField::load(other, s.scene.fingerprint() ^ 1u), std::runtime_error);
  std::stringstream truncated(saved.substr(0, saved.size() / 2));
  EXPECT_THROW(GuideField::load(truncated, s.scene.fingerprint()), std::runtime_error);
}

// --- Learning works ------------------------------------------------------------

// Once the field has learned, guided paths find light more often: the last
// pass's fraction of samples with exactly zero radiance drops below the
// unguided one. With 8 spp x 1728 pixels in the last pass, the binomial
// standard error of the difference is ~0.002 (door-ajar) and ~0.005
// (shelter); over seeds 1-20 the drops were 0.011-0.016 (4.7-7.1 standard
// errors) and 0.020-0.040 (3.8-7.5). Requiring 3 keeps the claim
// statistically significant without being fragile. Both renders use the
// same seed; the correlation that brings only makes the true standard error
// of the difference smaller than the independent-samples one used here.
TEST(GuidedLearning, FewerZeroRadiancePathsOnHardScenes) {
  for (const char* name : {"door-ajar", "shelter"}) {
    GuidedScene s(shipped(name, 48, 36, 64, 8));
    RenderOptions opt;
    opt.seed = 1;
    opt.guide_learn.all_spp = UINT32_MAX;  // this tiny image learns from every sample
    GuideField guide = s.make_guide();
    RenderResult g = s.run(&guide, opt), u = s.run(nullptr, opt);
    const PassStats &pg = g.stats.pass_stats.back(), &pu = u.stats.pass_stats.back();
    ASSERT_EQ(pg.samples, pu.samples);
    ASSERT_GE(pg.spp, 8u);
    const double fg = double(pg.zero_radiance) / pg.samples, fu = double(pu.zero_radiance) / pu.samples;
    const double se = std::sqrt(fg * (1 - fg) / pg.samples + fu * (1 - fu) / pu.samples);
    EXPECT_GT(fu - fg, 3.0 * se) << name << ": zero-radiance fraction guided " << fg << ", unguided " << fu;
  }
}

// Guided roulette keeps alive the paths the guide expects to bring light: on
// door-ajar (lit through a door gap) the last pass has fewer zero-radiance
// paths and longer paths than the same guided render with pbrt's throughput
// roulette, the guide decides roulette at many vertices, and the two images
// agree. With it off, no roulette decision is the guide's.
TEST(GuidedRoulette, KeepsPathsThatFindLightAndStaysUnbiased) {
  GuidedScene s(shipped("door-ajar", 48, 36, 64, 16));
  RenderOptions on = seeded(11), off = seeded(12);
  off.guide_roulette = false;
  GuideField g_on = s.make_guide(), g_off = s.make_guide();
  RenderResult r_on = s.run(&g_on, on), r_off = s.run(&g_off, off);
  EXPECT_GT(r_on.stats.counters.path.guided_roulette, r_on.stats.counters.path.vertices / 10);
  EXPECT_EQ(r_off.stats.counters.path.guided_roulette, 0u);
  const PassStats &p_on = r_on.stats.pass_stats.back(), &p_off = r_off.stats.pass_stats.back();
  ASSERT_EQ(p_on.samples, p_off.samples);
  const double f_on = double(p_on.zero_radiance) / p_on.samples, f_off = double(p_off.zero_radiance) / p_off.samples;
  const double se = std::sqrt(f_on * (1 - f_on) / p_on.samples + f_off * (1 - f_off) / p_off.samples);
  EXPECT_GT(f_off - f_on, 3.0 * se) << "zero-radiance fraction guided roulette " << f_on << ", throughput " << f_off;
  EXPECT_GT(double(p_on.vertices) / p_on.samples, 1.2 * double(p_off.vertices) / p_off.samples);
  expect_clean_guided_run(r_on, "guided roulette");
  expect_agree(channel_stats(r_on.film), channel_stats(r_off.film), "guided vs throughput roulette");
}

}  // namespace
}  // namespace tessera
