// Alpha cutouts (pbrt-v4 "alpha"): a surface of alpha a lets through 1 - a of
// what is behind it, for camera rays and shadow rays alike, independently per
// layer; alpha textures cut shapes out.
#include <gtest/gtest.h>

#include "render_helpers.h"

namespace tessera {
namespace {

// A two-sided emitter (L = 1) filling the view at z = 10, behind `occluders`.
// Black occluders: what the camera sees is the emitter's share let through.
double see_through(const std::string& occluders) {
  const std::string scene = R"(
LookAt 0 0 0  0 0 1  0 1 0
Camera "perspective" "float fov" [ 20 ]
Film "rgb" "integer xresolution" [ 16 ] "integer yresolution" [ 16 ]
Sampler "independent" "integer pixelsamples" [ 256 ]
Integrator "path" "integer maxdepth" [ 1 ]
WorldBegin
AttributeBegin
AreaLightSource "diffuse" "rgb L" [ 1 1 1 ] "bool twosided" true
Shape "trianglemesh" "point3 P" [ -100 -100 10  100 -100 10  100 100 10  -100 100 10 ] "integer indices" [ 0 1 2 0 2 3 ]
AttributeEnd
Material "diffuse" "rgb reflectance" [ 0 0 0 ]
)" + occluders;
  return testing::image_mean(film_mean(testing::render_text(scene).film));
}

std::string quad_at(double z, const std::string& alpha) {
  return "Shape \"trianglemesh\" \"point3 P\" [ -50 -50 " + std::to_string(z) + "  50 -50 " + std::to_string(z) +
         "  50 50 " + std::to_string(z) + "  -50 50 " + std::to_string(z) +
         " ] \"integer indices\" [ 0 1 2 0 2 3 ] \"point2 uv\" [ 0 0 1 0 1 1 0 1 ] " + alpha + "\n";
}

TEST(Alpha, CameraRaysPassInProportionToOneMinusAlphaPerLayer) {
  EXPECT_NEAR(see_through(""), 1.0, 1e-6);
  EXPECT_NEAR(see_through(quad_at(5, "")), 0.0, 1e-6);                                // opaque
  EXPECT_NEAR(see_through(quad_at(5, "\"float alpha\" 0")), 1.0, 1e-6);               // invisible
  EXPECT_NEAR(see_through(quad_at(5, "\"float alpha\" 0.25")), 0.75, 0.01);           // 65536 samples
  // Two layers decide independently: 0.5 * 0.5 pass both.
  EXPECT_NEAR(see_through(quad_at(5, "\"float alpha\" 0.5") + quad_at(6, "\"float alpha\" 0.5")), 0.25, 0.01);
}

TEST(Alpha, TexturedAlphaIsEvaluatedAtTheHit) {
  // Checks of alpha 0 and 1: only the cut-out half shows the emitter. Checks
  // of alpha 0.2 and 0.6, about 70 across the view: on average 1 - 0.4 passes.
  auto checks = [](const char* a, const char* b) {
    return std::string("Texture \"checks\" \"float\" \"checkerboard\" \"float uscale\" 4000 \"float vscale\" 4000 "
                       "\"float tex1\" ") + a + " \"float tex2\" " + b + "\n";
  };
  EXPECT_NEAR(see_through(checks("0", "1") + quad_at(5, "\"texture alpha\" \"checks\"")), 0.5, 0.02);
  EXPECT_NEAR(see_through(checks("0.2", "0.6") + quad_at(5, "\"texture alpha\" \"checks\"")), 0.6, 0.02);
}

TEST(Alpha, ShadowRaysPassTheSameShare) {
  // A point light above a diffuse floor with a half-transparent sheet between:
  // the floor's direct light halves.
  auto floor_light = [](const std::string& sheet) {
    const std::string scene = R"(
LookAt 0 5 0  0 0 0  0 0 1
Camera "perspective" "float fov" [ 10 ]
Film "rgb" "integer xresolution" [ 8 ] "integer yresolution" [ 8 ]
Sampler "independent" "integer pixelsamples" [ 512 ]
Integrator "path" "integer maxdepth" [ 1 ]
WorldBegin
LightSource "point" "rgb I" [ 4 4 4 ] "point3 from" [ 0 2 0 ]
Material "diffuse" "rgb reflectance" [ 0.5 0.5 0.5 ]
Shape "trianglemesh" "point3 P" [ -10 0 -10  10 0 -10  10 0 10  -10 0 10 ] "integer indices" [ 0 1 2 0 2 3 ]
)" + sheet;
    return testing::image_mean(film_mean(testing::render_text(scene).film));
  };
  // The camera (y = 5) looks through the sheet (y = 1) too.
  const std::string sheet =
      "Material \"diffuse\" \"rgb reflectance\" [ 0 0 0 ]\n"
      "Shape \"trianglemesh\" \"point3 P\" [ -10 1 -10  -10 1 10  10 1 10  10 1 -10 ] \"integer indices\" [ 0 1 2 0 2 3 ] "
      "\"float alpha\" 0.5\n";
  const double open = floor_light(""), covered = floor_light(sheet);
  ASSERT_GT(open, 0.0);
  // Camera rays pass the sheet half the time, and so do shadow rays: 1/4.
  EXPECT_NEAR(covered / open, 0.25, 0.02);
}

}  // namespace
}  // namespace tessera
