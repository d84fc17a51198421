// Same seed -> bit-identical image, whatever the thread count or tile size;
// a different seed -> a different image.
#include <gtest/gtest.h>

#include <cstring>

#include "render_helpers.h"
#include "scene/builtin_scenes.h"
#include "scene/pbrt_loader.h"

namespace tessera {
namespace {

RenderResult render_cornell(int threads, int tile, uint64_t seed, SamplerKind sampler = SamplerKind::Independent) {
  SceneDesc d = load_builtin_cornell_box();
  d.film.xres = 48;
  d.film.yres = 40;
  d.spp = 6;
  d.sampler = sampler;
  RenderOptions opt;
  opt.threads = threads;
  opt.tile_size = tile;
  opt.seed = seed;
  return testing::render_desc(std::move(d), opt);
}

TEST(Determinism, BitIdenticalAcrossThreadCountsAndTiles) {
  RenderResult one = render_cornell(1, 16, 42);
  RenderResult two = render_cornell(2, 16, 42);
  RenderResult four = render_cornell(4, 7, 42);
  EXPECT_TRUE(testing::films_identical(one.film, two.film));
  EXPECT_TRUE(testing::films_identical(one.film, four.film));
  EXPECT_EQ(one.stats.counters.path.rays, four.stats.counters.path.rays);
}

TEST(Determinism, EverySamplerIsBitIdenticalAcrossThreadCountsAndTiles) {
  for (SamplerKind kind : {SamplerKind::Sobol, SamplerKind::ZSobol, SamplerKind::Stratified, SamplerKind::Halton}) {
    RenderResult one = render_cornell(1, 16, 42, kind);
    RenderResult four = render_cornell(4, 7, 42, kind);
    EXPECT_TRUE(testing::films_identical(one.film, four.film)) << static_cast<int>(kind);
    EXPECT_FALSE(testing::films_identical(one.film, render_cornell(1, 16, 42).film));
  }
}

// At equal samples, stratified points converge faster than independent ones
// on a soft shadow (direct light from an area light, one bounce): the error
// against a converged render is at least 1.5x lower for every
// low-discrepancy sampler.
TEST(Determinism, LowDiscrepancySamplersBeatIndependentNumbersAtEqualSamples) {
  const std::string scene = R"(
LookAt 0 4 0  0 0 0  0 0 1
Camera "perspective" "float fov" [ 40 ]
Film "rgb" "integer xresolution" [ 24 ] "integer yresolution" [ 24 ]
Sampler "independent" "integer pixelsamples" [ 16 ]
Integrator "path" "integer maxdepth" [ 1 ]
WorldBegin
AttributeBegin
AreaLightSource "diffuse" "rgb L" [ 4 4 4 ]
Shape "trianglemesh" "point3 P" [ -0.5 2 -0.5  -0.5 2 0.5  0.5 2 0.5  0.5 2 -0.5 ] "integer indices" [ 0 1 2 0 2 3 ]
AttributeEnd
Material "diffuse" "rgb reflectance" [ 0.5 0.5 0.5 ]
Shape "trianglemesh" "point3 P" [ -0.3 1 -0.3  -0.3 1 0.3  0.3 1 0.3  0.3 1 -0.3 ] "integer indices" [ 0 1 2 0 2 3 ]
Shape "trianglemesh" "point3 P" [ -5 0 -5  5 0 -5  5 0 5  -5 0 5 ] "integer indices" [ 0 1 2 0 2 3 ]
)";
  auto render_with = [&](SamplerKind k, int spp, uint64_t seed) {
    SceneDesc d = load_pbrt_string(scene, "<shadow>", ".");
    d.spp = spp;
    d.sampler = k;
    RenderOptions opt;
    opt.seed = seed;
    return film_mean(testing::render_desc(std::move(d), opt).film);
  };
  const ImageRgb truth = render_with(SamplerKind::Sobol, 4096, 99);
  auto mse = [&](const ImageRgb& img) {
    double s = 0;
    for (size_t i = 0; i < img.rgb.size(); ++i) s += (img.rgb[i] - truth.rgb[i]) * (img.rgb[i] - truth.rgb[i]);
    return s / img.rgb.size();
  };
  double independent = 0, padded = 0, zsobol = 0, stratified = 0, halton = 0;
  for (uint64_t seed = 1; seed <= 4; ++seed) {
    independent += mse(render_with(SamplerKind::Independent, 16, seed));
    padded += mse(render_with(SamplerKind::Sobol, 16, seed));
    zsobol += mse(render_with(SamplerKind::ZSobol, 16, seed));
    stratified += mse(render_with(SamplerKind::Stratified, 16, seed));
    halton += mse(render_with(SamplerKind::Halton, 16, seed));
  }
  EXPECT_LT(padded * 1.5, independent) << "paddedsobol " << padded << " independent " << independent;
  EXPECT_LT(zsobol * 1.5, independent) << "zsobol " << zsobol << " independent " << independent;
  EXPECT_LT(stratified * 1.5, independent) << "stratified " << stratified << " independent " << independent;
  EXPECT_LT(halton * 1.5, independent) << "halton " << halton << " independent " << independent;
}

TEST(Determinism, SeedChangesTheImage) {
  RenderResult a = render_cornell(2, 16, 1);
  RenderResult b = render_cornell(2, 16, 2);
  EXPECT_FALSE(testing::films_identical(a.film, b.film));
}

}  // namespace
}  // namespace tessera
