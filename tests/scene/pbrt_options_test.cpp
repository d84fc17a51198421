// Camera, Film, Sampler, Integrator and PixelFilter, and warnings.
#include "scene/pbrt_film.h"
#include "scene/sampler_setup.h"
#include "scene_test_helpers.h"

namespace tessera {
namespace {

SceneDesc load_with_options(const std::string& options) {
  return load_pbrt_string(options + "WorldBegin\n" + test::kTriangle, "opt.pbrt", ".");
}

bool has_warning(const SceneDesc& s, const std::string& part) {
  for (const std::string& w : s.warnings)
    if (w.find(part) != std::string::npos) return true;
  return false;
}

TEST(PbrtOptions, Defaults) {
  SceneDesc s = load_with_options("");
  EXPECT_EQ(s.film.xres, 1280);
  EXPECT_EQ(s.film.yres, 720);
  EXPECT_EQ(s.spp, 16);
  EXPECT_EQ(s.max_depth, 5);
  EXPECT_EQ(s.filter.type, FilterType::Gaussian);
  EXPECT_FLOAT_EQ(s.filter.radius, 1.5f);
  EXPECT_FLOAT_EQ(s.filter.sigma, 0.5f);
  EXPECT_EQ(s.sampler, SamplerKind::ZSobol);
  EXPECT_EQ(s.light_sampler, LightSamplerKind::Bvh);
  EXPECT_EQ(s.materials.size(), 1u);
  EXPECT_EQ(s.materials[0].type, MaterialType::Diffuse);
  EXPECT_FLOAT_EQ(s.materials[0].reflectance.value.x, 0.5f);
  EXPECT_TRUE(s.warnings.empty());
}

TEST(PbrtOptions, FilmSamplerIntegrator) {
  SceneDesc s = load_with_options(
      "Film \"gbuffer\" \"integer xresolution\" [ 64 ] \"integer yresolution\" 32 \"string filename\" \"a.exr\"\n"
      "Sampler \"zsobol\" \"integer pixelsamples\" 128 \"integer seed\" 7\n"
      "Integrator \"path\" \"integer maxdepth\" [ 3 ]\n");
  EXPECT_EQ(s.film.xres, 64);
  EXPECT_EQ(s.film.yres, 32);
  EXPECT_EQ(s.film.filename, "a.exr");
  EXPECT_EQ(s.spp, 128);
  EXPECT_EQ(s.seed, 7u);
  EXPECT_EQ(s.max_depth, 3);
  EXPECT_EQ(s.sampler, SamplerKind::ZSobol);
  EXPECT_TRUE(s.warnings.empty());
  EXPECT_EQ(load_with_options("Sampler \"independent\"\n").sampler, SamplerKind::Independent);
  EXPECT_EQ(load_with_options("").sampler, SamplerKind::ZSobol);  // pbrt's default
  const SceneDesc padded = load_with_options("Sampler \"paddedsobol\"\n");
  EXPECT_EQ(padded.sampler, SamplerKind::Sobol);
  EXPECT_TRUE(padded.warnings.empty());
  const SceneDesc halton = load_with_options("Sampler \"halton\" \"string randomization\" \"permutedigits\"\n");
  EXPECT_EQ(halton.sampler, SamplerKind::Halton);
  EXPECT_TRUE(halton.warnings.empty());
  EXPECT_EQ(halton.halton_randomize, HaltonRandomize::PermuteDigits);
  EXPECT_EQ(load_with_options("Sampler \"halton\" \"string randomization\" \"owen\"\n").halton_randomize,
            HaltonRandomize::Owen);
  EXPECT_EQ(load_with_options("Sampler \"halton\" \"string randomization\" \"none\"\n").halton_randomize,
            HaltonRandomize::None);
  EXPECT_THROW(load_with_options("Sampler \"halton\" \"string randomization\" \"fastowen\"\n"), SceneError);
  // pbrt's global "sobol" ordering is not reproduced, nor pmj02bn's points: said so.
  const SceneDesc sobol = load_with_options("Sampler \"sobol\"\n");
  EXPECT_EQ(sobol.sampler, SamplerKind::Sobol);
  ASSERT_EQ(sobol.warnings.size(), 1u);
  EXPECT_NE(sobol.warnings[0].find("drawn as \"paddedsobol\""), std::string::npos) << sobol.warnings[0];
  for (const char* other : {"pmj02bn"}) {
    const SceneDesc d = load_with_options(std::string("Sampler \"") + other + "\"\n");
    EXPECT_EQ(d.sampler, SamplerKind::ZSobol);
    ASSERT_EQ(d.warnings.size(), 1u);
    EXPECT_NE(d.warnings[0].find("drawn as \"zsobol\""), std::string::npos) << d.warnings[0];
  }
}

// pbrt-v4's stratified sampler takes xsamples x ysamples (pixelsamples is not
// read) and "jitter". --spp changes neither the strata nor zsobol's epoch
// (checkpoints resume with any --spp).
TEST(PbrtOptions, StratifiedSamplerReadsItsStrata) {
  const SceneDesc s = load_with_options(
      "Sampler \"stratified\" \"integer xsamples\" 3 \"integer ysamples\" 5 \"bool jitter\" false "
      "\"integer pixelsamples\" 64\n");
  EXPECT_EQ(s.sampler, SamplerKind::Stratified);
  EXPECT_EQ(s.spp, 15);
  SamplerSetup setup = sampler_setup(s);
  EXPECT_EQ(setup.strata_x, 3u);
  EXPECT_EQ(setup.strata_y, 5u);
  EXPECT_FALSE(setup.jitter);
  SceneDesc overridden = s;
  overridden.spp = 24;
  setup = sampler_setup(overridden);
  EXPECT_EQ(setup.strata_x, 3u);
  EXPECT_EQ(setup.strata_y, 5u);
  SceneDesc z = load_with_options("Sampler \"zsobol\" \"integer pixelsamples\" 100\n");
  EXPECT_EQ(sampler_setup(z).log2_spp, 7u);
  z.spp = 4096;
  EXPECT_EQ(sampler_setup(z).log2_spp, 7u);
  EXPECT_THROW(load_with_options("Sampler \"stratified\" \"integer xsamples\" 0\n"), std::exception);
  // 65536 x 65536 strata overflowed int.
  EXPECT_THROW(load_with_options("Sampler \"stratified\" \"integer xsamples\" 65536 \"integer ysamples\" 65536\n"),
               std::exception);
}

TEST(PbrtOptions, OtherIntegratorsWarn) {
  SceneDesc s = load_with_options("Integrator \"bdpt\" \"integer maxdepth\" [ 9 ]\n");
  EXPECT_EQ(s.max_depth, 9);
  EXPECT_TRUE(has_warning(s, "opt.pbrt:1: integrator \"bdpt\""));
}

TEST(PbrtOptions, PixelFilters) {
  SceneDesc s = load_with_options("PixelFilter \"box\"\n");
  EXPECT_EQ(s.filter.type, FilterType::Box);
  EXPECT_FLOAT_EQ(s.filter.radius, 0.5f);
  s = load_with_options("PixelFilter \"gaussian\" \"float xradius\" 2 \"float yradius\" 2 \"float sigma\" 0.25\n");
  EXPECT_EQ(s.filter.type, FilterType::Gaussian);
  EXPECT_FLOAT_EQ(s.filter.radius, 2.f);
  EXPECT_FLOAT_EQ(s.filter.sigma, 0.25f);
  s = load_with_options("PixelFilter \"mitchell\" \"float B\" 0.3\n");
  EXPECT_EQ(s.filter.type, FilterType::Mitchell);
  EXPECT_FLOAT_EQ(s.filter.b, 0.3f);
  EXPECT_FLOAT_EQ(s.filter.c, 1.f / 3.f);
  EXPECT_FLOAT_EQ(s.filter.radius, 2.f);
  s = load_with_options("PixelFilter \"triangle\" \"float yradius\" 1\n");
  EXPECT_EQ(s.filter.type, FilterType::Triangle);
  EXPECT_FLOAT_EQ(s.filter.radius, 2.f);
  EXPECT_FLOAT_EQ(s.filter.radius_y, 1.f);
  s = load_with_options("PixelFilter \"sinc\"\n");
  EXPECT_EQ(s.filter.type, FilterType::LanczosSinc);
  EXPECT_FLOAT_EQ(s.filter.radius, 4.f);
  EXPECT_FLOAT_EQ(s.filter.tau, 3.f);
  s = load_with_options("PixelFilter \"catmullrom\"\n");
  EXPECT_EQ(s.filter.type, FilterType::Gaussian);
  EXPECT_TRUE(has_warning(s, "opt.pbrt:1: pixel filter \"catmullrom\" is unknown"));
  EXPECT_NE(test::load_error("PixelFilter \"box\" \"float xradius\" 0\nWorldBegin\n").find("radii must be in"), std::string::npos);
}

TEST(PbrtOptions, FilterFunctionsArePbrtsDefinitions) {
  FilterDesc m;
  m.type = FilterType::Mitchell;
  // Mitchell-Netravali at B = C = 1/3: (6 - 2B)/6 at the centre, B/6 at half the radius, negative beyond.
  EXPECT_NEAR(pixel_filter_1d(m, 0.f, 2.f), (6.f - 2.f / 3.f) / 6.f, 1e-6f);
  EXPECT_NEAR(pixel_filter_1d(m, 1.f, 2.f), 1.f / 18.f, 1e-6f);
  EXPECT_LT(pixel_filter_1d(m, 1.5f, 2.f), 0.f);
  EXPECT_EQ(pixel_filter_1d(m, 2.1f, 2.f), 0.f);
  FilterDesc t;
  t.type = FilterType::Triangle;
  EXPECT_FLOAT_EQ(pixel_filter_1d(t, -0.5f, 2.f), 1.5f);
  FilterDesc l;
  l.type = FilterType::LanczosSinc;
  EXPECT_NEAR(pixel_filter_1d(l, 0.f, 4.f), 1.f, 1e-6f);
  EXPECT_NEAR(pixel_filter_1d(l, 1.f, 4.f), 0.f, 1e-6f);  // sinc's first zero
  EXPECT_LT(pixel_filter_1d(l, 1.5f, 4.f), 0.f);
}

TEST(PbrtOptions, CameraTypesAndLensWarn) {
  SceneDesc s = load_with_options("Camera \"realistic\" \"string lensfile\" \"wide.dat\"\n");
  EXPECT_TRUE(has_warning(s, "opt.pbrt:1: camera \"realistic\" treated as \"perspective\""));
  s = load_with_options("Camera \"orthographic\" \"float lensradius\" 0.2\n");
  EXPECT_TRUE(s.warnings.empty());
  EXPECT_EQ(s.camera.projection, CameraProjection::Orthographic);
  s = load_with_options("Camera \"spherical\" \"string mapping\" \"equirectangular\"\n");
  EXPECT_TRUE(s.warnings.empty());
  EXPECT_EQ(s.camera.projection, CameraProjection::SphericalEquirectangular);
  s = load_with_options("Camera \"perspective\" \"float lensradius\" 0.1 \"float focaldistance\" 3\n");
  EXPECT_TRUE(s.warnings.empty());
  EXPECT_FLOAT_EQ(s.camera.lens_radius, 0.1f);
  EXPECT_FLOAT_EQ(s.camera.focal_distance, 3.f);
  EXPECT_NE(test::load_error("Camera \"perspective\" \"float focaldistance\" 0\nWorldBegin\n").find("focaldistance"),
            std::string::npos);
}

TEST(PbrtOptions, UnknownParametersAndDirectivesWarnWithLocation) {
  SceneDesc s = load_pbrt_string("Film \"rgb\" \"float isoo\" 100\nWorldBegin\nFoo 1 2 \"x\"\nColorSpace \"aces2065-1\"\n"
                                 "Shape \"sphere\" \"float radius\" 1 \"float bogus\" 2\n",
                                 "w.pbrt", ".");
  EXPECT_TRUE(has_warning(s, "w.pbrt:1: unknown parameter 'isoo' for Film \"rgb\""));
  EXPECT_TRUE(has_warning(s, "w.pbrt:3: unknown directive 'Foo'"));
  EXPECT_TRUE(has_warning(s, "w.pbrt:4: 'ColorSpace' is not supported"));
  EXPECT_TRUE(has_warning(s, "w.pbrt:5: unknown parameter 'bogus' for Shape \"sphere\""));
  EXPECT_EQ(s.meshes.size(), 1u);
}

}  // namespace
}  // namespace tessera
