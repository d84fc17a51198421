// Scenes with analytic radiance. A closed emitting sphere of albedo rho seen
// from inside has, with pbrt's depth counting, L = Le * sum_{k=0..D} rho^k at
// every pixel: the estimator's mean must match it whatever the sampling
// strategy (NEE+MIS or BSDF sampling only).
#include <gtest/gtest.h>

#include <cmath>

#include "furnace_scene.h"
#include "render_helpers.h"

namespace tessera {
namespace {

using testing::expected_furnace;
using testing::furnace_scene;

// Tolerance: 256 spp x 256 pixels = 65k paths; the per-path standard
// deviation is below 1 for these scenes, so 1% is > 5 standard errors.
constexpr double kRelTol = 0.01;

TEST(Furnace, ClosedSphereWithNee) {
  for (int depth : {1, 5}) {
    RenderResult r = testing::render_text(furnace_scene(0.5, depth));
    double mean = testing::image_mean(film_mean(r.film));
    EXPECT_NEAR(mean, expected_furnace(0.5, depth), kRelTol * expected_furnace(0.5, depth)) << "depth " << depth;
    EXPECT_EQ(r.stats.counters.rejected_nonfinite, 0u);
  }
}

TEST(Furnace, ClosedSphereWithoutNee) {
  RenderOptions opt;
  opt.nee = false;
  RenderResult r = testing::render_text(furnace_scene(0.5, 5), opt);
  double mean = testing::image_mean(film_mean(r.film));
  EXPECT_NEAR(mean, expected_furnace(0.5, 5), kRelTol * expected_furnace(0.5, 5));
}

TEST(Furnace, HighAlbedoDeepPaths) {
  // rho = 0.9, depth 40: sum = (1 - 0.9^41) / 0.1 = 9.867; Russian roulette does most of the work.
  RenderResult r = testing::render_text(furnace_scene(0.9, 40));
  double mean = testing::image_mean(film_mean(r.film));
  EXPECT_NEAR(mean, expected_furnace(0.9, 40), 0.02 * expected_furnace(0.9, 40));
}

// Albedo 1 at depth 1000: every path must stay inside the tessellated
// sphere for all 1000 bounces. Two ways out are closed: a direction
// sampled around the shading normal that falls through its facet (it is
// mirrored across the face; without that 7 % of the light escapes), and a
// ray through the edge between two facets (Embree's robust traversal,
// which AVX2 builds of Embree need).
TEST(Furnace, AlbedoOneAtDepthThousandLosesNothing) {
  RenderResult r = testing::render_text(furnace_scene(1.0, 1000, 8, 8));
  const double mean = testing::image_mean(film_mean(r.film));
  EXPECT_NEAR(mean, 1001.0, 0.002 * 1001.0);
  const double vertices_per_path =
      static_cast<double>(r.stats.counters.path.vertices) / static_cast<double>(r.stats.counters.samples);
  EXPECT_GT(vertices_per_path, 999.0);
}

// A reflectance above 1 is an albedo clamped to 1 (as pbrt-v4's albedo
// spectra are), in RGB and spectral transport alike: never a surface that
// creates light.
TEST(Furnace, ReflectanceAboveOneIsClampedToOne) {
  for (bool spectral : {false, true}) {
    SceneDesc d = load_pbrt_string(furnace_scene(1.5, 3), "<test>", ".");
    d.spectral = spectral;
    RenderResult r = testing::render_desc(std::move(d), RenderOptions{});
    const double mean = testing::image_mean(film_mean(r.film));
    EXPECT_NEAR(mean, expected_furnace(1.0, 3), kRelTol * expected_furnace(1.0, 3)) << "spectral " << spectral;
  }
}

TEST(Furnace, NeeAndBsdfSamplingAgree) {
  RenderOptions a, b;
  b.nee = false;
  double ma = testing::image_mean(film_mean(testing::render_text(furnace_scene(0.7, 3), a).film));
  double mb = testing::image_mean(film_mean(testing::render_text(furnace_scene(0.7, 3), b).film));
  EXPECT_NEAR(ma, mb, 0.01 * ma);
}

TEST(Furnace, ConvexObjectUnderConstantEnvironment) {
  // A convex diffuse object under a uniform environment L = 1 reflects exactly
  // rho (it never sees itself); background pixels see L = 1.
  const char* scene = R"(
LookAt 0 0 -5  0 0 0  0 1 0
Camera "perspective" "float fov" [ 20 ]
Film "rgb" "integer xresolution" [ 32 ] "integer yresolution" [ 32 ]
Sampler "independent" "integer pixelsamples" [ 256 ]
Integrator "path" "integer maxdepth" [ 5 ]
WorldBegin
LightSource "infinite" "rgb L" [ 1 1 1 ]
Material "diffuse" "rgb reflectance" [ 0.6 0.6 0.6 ]
Shape "sphere" "float radius" [ 1 ]
)";
  ImageRgb img = film_mean(testing::render_text(scene).film);
  // Central 8x8 pixels are on the sphere (it spans ~ +-0.2 rad of the 0.35 rad fov).
  double centre = 0;
  for (int y = 12; y < 20; ++y)
    for (int x = 12; x < 20; ++x)
      for (int c = 0; c < 3; ++c) centre += img.rgb[3 * (y * 32 + x) + c];
  centre /= 8 * 8 * 3;
  EXPECT_NEAR(centre, 0.6, 0.01);
  double corner = (img.rgb[0] + img.rgb[1] + img.rgb[2]) / 3;
  EXPECT_NEAR(corner, 1.0, 1e-5);
}

}  // namespace
}  // namespace tessera
