// Camera, Film, Sampler, Integrator and PixelFilter, and warnings.
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
  EXPECT_TRUE(s.warnings.empty());
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
  EXPECT_EQ(s.filter.type, FilterType::Gaussian);
  EXPECT_TRUE(has_warning(s, "opt.pbrt:1: pixel filter \"mitchell\""));
}

TEST(PbrtOptions, CameraTypesAndLensWarn) {
  SceneDesc s = load_with_options("Camera \"orthographic\"\n");
  EXPECT_TRUE(has_warning(s, "opt.pbrt:1: camera \"orthographic\""));
  s = load_with_options("Camera \"perspective\" \"float lensradius\" 0.1 \"float focaldistance\" 3\n");
  EXPECT_TRUE(has_warning(s, "depth of field"));
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
