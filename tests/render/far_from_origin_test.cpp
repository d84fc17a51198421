// Scenes far from the world's origin render as they do at the origin: the
// parser composes transforms in double and places everything in render
// space (the camera at the origin, as pbrt-v4's "cameraworld"), so float
// precision is spent near the camera, not on the distance to the origin.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "render_helpers.h"

namespace tessera {
namespace {

// A glossy sphere, a glass sphere and a floor under an area light, the
// camera and the world both moved by (t, 0, t / 2).
std::string moved_scene(const std::string& t, const std::string& half_t) {
  return "LookAt " + t + " 1.5 " + half_t + "  " + t + " 0.6 " + half_t + "  0 0 1\n" + R"(
Camera "perspective" "float fov" [ 50 ]
Film "rgb" "integer xresolution" [ 32 ] "integer yresolution" [ 24 ]
Sampler "independent" "integer pixelsamples" [ 16 ]
Integrator "path" "integer maxdepth" [ 8 ]
WorldBegin
)" + "Translate " + t + " 0 " + half_t + "\n" + R"(
AttributeBegin
  AreaLightSource "diffuse" "rgb L" [ 8 8 8 ]
  Shape "trianglemesh" "point3 P" [ -0.5 2 2  0.5 2 2  0.5 2 3  -0.5 2 3 ] "integer indices" [ 0 1 2 0 2 3 ]
AttributeEnd
Material "diffuse" "rgb reflectance" [ 0.6 0.6 0.6 ]
Shape "trianglemesh" "point3 P" [ -3 0 0  3 0 0  3 0 6  -3 0 6 ] "integer indices" [ 0 1 2 0 2 3 ]
AttributeBegin
  Material "conductor" "float roughness" [ 0.05 ]
  Translate -0.5 0.4 3
  Shape "sphere" "float radius" [ 0.4 ]
AttributeEnd
AttributeBegin
  Material "dielectric" "float eta" [ 1.5 ]
  Translate 0.5 0.3 2.5
  Shape "sphere" "float radius" [ 0.3 ]
AttributeEnd
)";
}

TEST(FarFromOrigin, MovedScenesRenderAsAtTheOrigin) {
  RenderOptions opt;
  opt.seed = 3;
  const RenderResult home = testing::render_text(moved_scene("0", "0"), opt);
  const double home_mean = testing::image_mean(film_mean(home.film));
  ASSERT_GT(home_mean, 0.01);
  // Before render space, 1e4 lost 4 % of the light and 1e6 a quarter.
  for (const auto& [t, half_t] : {std::pair<std::string, std::string>{"1e4", "5e3"}, {"1e6", "5e5"}, {"1e12", "5e11"}}) {
    const RenderResult far = testing::render_text(moved_scene(t, half_t), opt);
    EXPECT_NEAR(testing::image_mean(film_mean(far.film)), home_mean, 1e-3 * home_mean) << "moved by " << t;
  }
}

// A point light over a huge plane lights the same spot under the camera as
// over a small one. Barycentric hit points of a plane 1e8 across are metres
// off (15 % of the light was lost), and a plane 1e10 across had a face
// normal whose length overflowed float (black): hits on huge triangles now
// take the ray's point projected onto the plane, and normals are computed in
// double.
TEST(FarFromOrigin, HugePlaneKeepsItsLight) {
  auto plane = [](const std::string& s) {
    return R"(
LookAt 0 2 0  0 0 0  0 0 1
Camera "perspective" "float fov" [ 60 ]
Film "rgb" "integer xresolution" [ 16 ] "integer yresolution" [ 16 ]
Sampler "independent" "integer pixelsamples" [ 8 ]
WorldBegin
LightSource "point" "point3 from" [ 0 1 0 ] "rgb I" [ 1 1 1 ]
Material "diffuse" "rgb reflectance" [ 0.5 0.5 0.5 ]
Shape "trianglemesh" "point3 P" [ -)" +
           s + " 0 -" + s + "  " + s + " 0 -" + s + "  " + s + " 0 " + s + "  -" + s + " 0 " + s +
           R"( ] "integer indices" [ 0 1 2 0 2 3 ]
)";
  };
  const double small = testing::image_mean(film_mean(testing::render_text(plane("10")).film));
  ASSERT_GT(small, 0.01);
  for (const char* size : {"1e6", "1e8", "1e10", "1e12"}) {
    const double huge = testing::image_mean(film_mean(testing::render_text(plane(size)).film));
    EXPECT_NEAR(huge, small, 0.001 * small) << "half-size " << size;
  }
}

}  // namespace
}  // namespace tessera
