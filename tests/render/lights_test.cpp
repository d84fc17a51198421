// Light sources against closed-form answers, and estimator agreement: the
// same scene rendered with NEE+MIS and with BSDF sampling alone must have the
// same expected value.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>

#include "render/image_output.h"
#include "render_helpers.h"

namespace tessera {
namespace {

constexpr double kPiD = 3.14159265358979323846;

// A diffuse plane (albedo 0.5) at y = 0 seen from straight above with a narrow
// fov; `light` is inserted after WorldBegin. Returns the mean of the central
// 4x4 pixels (green channel).
double centre_radiance(const std::string& light, int max_depth = 1) {
  std::string scene = R"(
LookAt 0 5 0  0 0 0  0 0 1
Camera "perspective" "float fov" [ 10 ]
Film "rgb" "integer xresolution" [ 16 ] "integer yresolution" [ 16 ]
Sampler "independent" "integer pixelsamples" [ 16 ]
Integrator "path" "integer maxdepth" [ )" + std::to_string(max_depth) + R"( ]
WorldBegin
)" + light + R"(
Material "diffuse" "rgb reflectance" [ 0.5 0.5 0.5 ]
Shape "trianglemesh" "point3 P" [ -10 0 -10  10 0 -10  10 0 10  -10 0 10 ] "integer indices" [ 0 1 2 0 2 3 ]
)";
  ImageRgb img = film_mean(testing::render_text(scene).film);
  double s = 0;
  for (int y = 6; y < 10; ++y)
    for (int x = 6; x < 10; ++x) s += img.rgb[3 * (y * 16 + x) + 1];
  return s / 16;
}

// The central pixels average over +-3.5 pixels (filter radius 1.5) around the
// foot point, where cos^3 falloff lowers irradiance by up to ~0.3%: tolerances
// of 0.6% cover that and still catch any wrong factor.
TEST(Lights, PointLightInverseSquare) {
  // L = rho / pi * I / h^2 at the foot of the light.
  double L = centre_radiance(R"(LightSource "point" "rgb I" [ 4 4 4 ] "point3 from" [ 0 2 0 ])");
  EXPECT_NEAR(L, 0.5 / kPiD * 4 / 4, 0.006 * 0.159);
}

TEST(Lights, PointLightScale) {
  double L = centre_radiance(R"(LightSource "point" "rgb I" [ 4 4 4 ] "float scale" [ 2 ] "point3 from" [ 0 2 0 ])");
  EXPECT_NEAR(L, 2 * 0.5 / kPiD, 0.012 * 0.159);
}

TEST(Lights, SpotLightCentreAndOutside) {
  double centre = centre_radiance(
      R"(LightSource "spot" "rgb I" [ 4 4 4 ] "point3 from" [ 0 2 0 ] "point3 to" [ 0 0 0 ] "float coneangle" [ 30 ])");
  EXPECT_NEAR(centre, 0.5 / kPiD, 0.006 * 0.159);
  // Aimed away (cone axis horizontal): the plane below is outside the cone.
  double outside = centre_radiance(
      R"(LightSource "spot" "rgb I" [ 4 4 4 ] "point3 from" [ 0 2 0 ] "point3 to" [ 5 2 0 ] "float coneangle" [ 30 ])");
  EXPECT_EQ(outside, 0.0);
}

TEST(Lights, DistantLightIrradiance) {
  // Light travelling straight down with radiance-scale 3: E = 3, L = rho E / pi.
  double L = centre_radiance(R"(LightSource "distant" "rgb L" [ 3 3 3 ] "point3 from" [ 0 1 0 ] "point3 to" [ 0 0 0 ])");
  EXPECT_NEAR(L, 0.5 * 3 / kPiD, 1e-3);
  // At 60 degrees incidence: E = 3 cos 60.
  double L60 = centre_radiance(
      R"(LightSource "distant" "rgb L" [ 3 3 3 ] "point3 from" [ 0.8660254 0.5 0 ] "point3 to" [ 0 0 0 ])");
  EXPECT_NEAR(L60, 0.5 * 1.5 / kPiD, 1e-3);
}

TEST(Lights, OneSidedAreaLightEmitsOnlyOnItsSide) {
  // A small downward-facing emitter (area 0.16) off to the side, out of view,
  // lights the plane; flipped by ReverseOrientation it faces up and the plane
  // stays dark (depth 1: no indirect light).
  const char* down = R"(AttributeBegin
Material "diffuse" "rgb reflectance" [ 0 0 0 ]
AreaLightSource "diffuse" "rgb L" [ 5 5 5 ]
Shape "trianglemesh" "point3 P" [ 2.8 1 -0.2  3.2 1 -0.2  3.2 1 0.2  2.8 1 0.2 ] "integer indices" [ 0 1 2 0 2 3 ]
AttributeEnd)";
  std::string up = std::string("ReverseOrientation\n") + down;
  double lit = centre_radiance(down), dark = centre_radiance(up);
  // Small-source approximation at distance^2 = 10 with both cosines 1/sqrt(10):
  // E = L A cos cos / d^2 = 5 * 0.16 * 0.1 / 10.
  const double expected = 0.5 / kPiD * 5 * 0.16 * 0.1 / 10;
  EXPECT_NEAR(lit, expected, 0.05 * expected);
  EXPECT_EQ(dark, 0.0);
}

class EnvironmentLight : public ::testing::Test {
 protected:
  // Writes a square equal-area environment map: top half `top`, bottom half `bottom`.
  void write_env(float top, float bottom) {
    ImageRgb img{32, 32, std::vector<float>(32 * 32 * 3)};
    for (int y = 0; y < 32; ++y)
      for (int x = 0; x < 32 * 3; ++x) img.rgb[y * 32 * 3 + x] = y < 16 ? top : bottom;
    write_exr(path_, img, nullptr, {});
  }
  std::string scene(int spp) const {
    return R"(
LookAt 0 0.5 -5  0 0 0  0 1 0
Camera "perspective" "float fov" [ 30 ]
Film "rgb" "integer xresolution" [ 24 ] "integer yresolution" [ 24 ]
Sampler "independent" "integer pixelsamples" [ )" + std::to_string(spp) + R"( ]
Integrator "path" "integer maxdepth" [ 4 ]
WorldBegin
AttributeBegin
  Rotate -90 1 0 0
  LightSource "infinite" "string filename" [ ")" + path_ + R"(" ]
AttributeEnd
Material "diffuse" "rgb reflectance" [ 0.6 0.6 0.6 ]
Shape "sphere" "float radius" [ 1 ]
Material "diffuse" "rgb reflectance" [ 0.3 0.3 0.3 ]
Shape "trianglemesh" "point3 P" [ -4 -1 -4  4 -1 -4  4 -1 4  -4 -1 4 ] "integer indices" [ 0 1 2 0 2 3 ]
)";
  }
  testing::TempFile file_{"env.exr"};
  const std::string& path_ = file_.path();
};

TEST_F(EnvironmentLight, ConstantImageMatchesConstantLight) {
  write_env(0.7f, 0.7f);
  double image = testing::image_mean(film_mean(testing::render_text(scene(64)).film));
  std::string constant = scene(64);
  constant.replace(constant.find("\"string filename\""), std::string("\"string filename\" [ \"" + path_ + "\" ]").size(),
                   "\"rgb L\" [ 0.7 0.7 0.7 ]");
  double reference = testing::image_mean(film_mean(testing::render_text(constant).film));
  EXPECT_NEAR(image, reference, 0.01 * reference);
}

TEST_F(EnvironmentLight, NeeAndBsdfSamplingAgree) {
  // Strongly non-uniform map: importance sampling and MIS weights must still
  // give the same expectation as BSDF sampling alone.
  write_env(8.0f, 0.05f);
  RenderOptions nee, bsdf_only;
  bsdf_only.nee = false;
  double a = testing::image_mean(film_mean(testing::render_text(scene(256), nee).film));
  double b = testing::image_mean(film_mean(testing::render_text(scene(256), bsdf_only).film));
  EXPECT_NEAR(a, b, 0.02 * a);
}

TEST(EstimatorAgreement, GlossyScene) {
  // Rough conductors, rough and smooth glass, a textured floor, an area light.
  auto render = [](bool nee) {
    SceneDesc d = load_pbrt_file(testing::source_dir() + "/scenes/glossy.pbrt");
    d.film.xres = 24;
    d.film.yres = 18;
    d.spp = 1024;
    RenderOptions opt;
    opt.nee = nee;
    return testing::image_mean(film_mean(testing::render_desc(std::move(d), opt).film));
  };
  double with_nee = render(true), without = render(false);
  EXPECT_NEAR(with_nee, without, 0.03 * with_nee);
}

}  // namespace
}  // namespace tessera
