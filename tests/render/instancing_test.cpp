// Object instancing (kernels/instance.h): a scene of ObjectInstances renders
// the picture of the same shapes written out one by one (its flattened
// form) on every backend, while the geometry is stored once.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <string>

#include "render/backends.h"
#include "render_helpers.h"
#include "scene/object_instances.h"

namespace tessera {
namespace {

// Under a quad light, on a floor: an object of a coated sphere, a triangle
// with shading normals and uv, and a quad cut out by a checkerboard alpha,
// placed 8 times by rotations, non-uniform scales and mirrors (which swap
// handedness). `end_motion` (after ActiveTransform EndTime) moves every copy.
std::string placed_objects(bool instanced, const std::string& end_motion = "") {
  std::string s = R"(LookAt 0 4 -9  0 0.5 0  0 1 0
Camera "perspective" "float fov" 40
Film "rgb" "integer xresolution" 48 "integer yresolution" 36
Sampler "independent" "integer pixelsamples" 64
WorldBegin
AttributeBegin
AreaLightSource "diffuse" "rgb L" [ 8 8 8 ]
Translate 0 6 0
Rotate 90 1 0 0
Shape "bilinearmesh" "point3 P" [ -1 -1 0  1 -1 0  -1 1 0  1 1 0 ]
AttributeEnd
Material "diffuse" "rgb reflectance" [ 0.5 0.5 0.5 ]
Shape "trianglemesh" "point3 P" [ -20 0 -20  20 0 -20  20 0 20  -20 0 20 ] "integer indices" [ 0 1 2  0 2 3 ]
Texture "cut" "float" "checkerboard" "float uscale" 4 "float vscale" 4 "float tex1" 0 "float tex2" 1
)";
  const std::string object = R"(Material "coateddiffuse" "rgb reflectance" [ 0.7 0.3 0.2 ] "float roughness" 0.1
Shape "sphere" "float radius" 0.5
Material "diffuse" "rgb reflectance" [ 0.2 0.6 0.3 ]
Translate 0 0.8 0
Shape "trianglemesh" "point3 P" [ -0.4 0 0  0.4 0 0  0 0.6 0.2 ] "integer indices" [ 0 1 2 ]
  "normal N" [ 0 0 -1  0.3 0 -1  0 0.3 -1 ] "point2 uv" [ 0 0  1 0  0.5 1 ]
Translate 0 0 -0.6
Shape "bilinearmesh" "point3 P" [ -0.5 0 0  0.5 0 0  -0.5 0.5 0  0.5 0.5 0 ] "texture alpha" "cut"
)";
  if (instanced) s += "ObjectBegin \"thing\"\n" + object + "ObjectEnd\n";
  for (int i = 0; i < 8; ++i) {
    s += "AttributeBegin\nTranslate " + std::to_string((i % 4) * 2.0 - 3.0) + " 0.5 " + std::to_string((i / 4) * 2.0 - 1.0) +
         "\nRotate " + std::to_string(i * 37) + " 0.3 1 0.2\nScale " + std::to_string(1.0 + 0.15 * i) + " " +
         std::to_string(1.2 - 0.1 * i) + (i % 3 == 1 ? " -1\n" : " 1\n");
    if (!end_motion.empty()) s += "ActiveTransform EndTime\n" + end_motion + "\nActiveTransform All\n";
    s += instanced ? "ObjectInstance \"thing\"\n" : object;
    s += "AttributeEnd\n";
  }
  return s;
}

ImageRgb render_on(const std::string& backend, const std::string& text, uint32_t spp = 64) {
  SceneData scene(load_pbrt_string(text, "<instances>", "."));
  std::unique_ptr<TileBackend> b = make_tile_backend(backend, scene, 2);
  return film_mean(render(scene, *b, testing::scene_options(scene, spp, 7)).film);
}

// Same seeds, same pixel samples: the two forms trace the same paths except
// where rounding in the instance's space tips a ray, so they agree far more
// closely than two independent renders would.
void expect_same_picture(const ImageRgb& a, const ImageRgb& b) {
  ASSERT_EQ(a.rgb.size(), b.rgb.size());
  double mean_a[3] = {}, mean_b[3] = {};
  for (size_t i = 0; i < a.rgb.size(); ++i) {
    ASSERT_TRUE(std::isfinite(a.rgb[i]));
    mean_a[i % 3] += a.rgb[i];
    mean_b[i % 3] += b.rgb[i];
  }
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(mean_a[c] / mean_b[c], 1.0, 0.01) << "channel " << c;
  for (int by = 0; by + 8 <= a.height; by += 8)
    for (int bx = 0; bx + 8 <= a.width; bx += 8) {
      double sa = 0, sb = 0;
      for (int y = by; y < by + 8; ++y)
        for (int x = bx; x < bx + 8; ++x)
          for (int c = 0; c < 3; ++c) {
            sa += a.rgb[3 * (y * a.width + x) + c];
            sb += b.rgb[3 * (y * a.width + x) + c];
          }
      EXPECT_NEAR(sa, sb, 0.05 * sb + 1e-3) << "8x8 block at " << bx << ", " << by;
    }
}

class InstancingOn : public ::testing::TestWithParam<std::string> {};

TEST_P(InstancingOn, InstancesRenderTheirFlattenedForm) {
  expect_same_picture(render_on(GetParam(), placed_objects(true)), render_on(GetParam(), placed_objects(false)));
}

// (At fewer samples: the flattened form's moving triangles have boxes as
// large as their sweep, slow on the portable BVH.)
TEST_P(InstancingOn, MovingInstancesRenderTheirFlattenedForm) {
  const std::string motion = "Translate 0.7 0.3 0\nRotate 25 0 1 0";
  expect_same_picture(render_on(GetParam(), placed_objects(true, motion), 16),
                      render_on(GetParam(), placed_objects(false, motion), 16));
}

INSTANTIATE_TEST_SUITE_P(Backends, InstancingOn, ::testing::Values("embree", "bvh", "emulated-device"));

TEST(Instancing, GeometryIsStoredOnce) {
  SceneDesc flat = load_pbrt_string(placed_objects(false), "<flat>", ".");
  SceneDesc inst = load_pbrt_string(placed_objects(true), "<instances>", ".");
  ASSERT_EQ(inst.objects.size(), 1u);
  EXPECT_EQ(inst.instances.size(), 8u);
  const GeometryCount f = count_geometry(flat), i = count_geometry(inst);
  const uint64_t floor_and_light = 4;
  EXPECT_EQ(i.triangles - floor_and_light, (f.triangles - floor_and_light) / 8);
  SceneData scene(std::move(inst));
  EXPECT_EQ(scene.view().num_instances, 8u);
  EXPECT_EQ(scene.view().num_world_triangles, floor_and_light);
}

// 3000 copies of a 16k-triangle sphere: 48M triangles flattened (gigabytes),
// one sphere and 3000 placements instanced.
TEST(Instancing, ThousandsOfInstancesRenderFromOneCopy) {
  std::string s = R"(LookAt 0 40 -80  0 0 0  0 1 0
Camera "perspective" "float fov" 45
Film "rgb" "integer xresolution" 40 "integer yresolution" 30
Sampler "independent" "integer pixelsamples" 1
WorldBegin
LightSource "infinite" "rgb L" [ 1 1 1 ]
ObjectBegin "ball"
Shape "sphere" "float radius" 0.8
ObjectEnd
)";
  for (int i = 0; i < 60; ++i)
    for (int j = 0; j < 50; ++j)
      s += "AttributeBegin\nTranslate " + std::to_string((i - 30) * 2) + " 0 " + std::to_string((j - 25) * 2) +
           "\nObjectInstance \"ball\"\nAttributeEnd\n";
  SceneData scene(load_pbrt_string(s, "<many>", "."));
  EXPECT_EQ(scene.view().num_instances, 3000u);
  EXPECT_LE(scene.num_triangles(), 20000u);
  for (const char* backend : {"embree", "bvh"}) {
    std::unique_ptr<TileBackend> b = make_tile_backend(backend, scene, 2);
    const ImageRgb img = film_mean(render(scene, *b, testing::scene_options(scene, 1, 1)).film);
    // The lower half of the view is balls under the sky: lit, and darker than the sky.
    double top = 0, bottom = 0;
    for (int y = 0; y < img.height; ++y)
      for (int x = 0; x < img.width; ++x) (y < img.height / 4 ? top : bottom) += img.rgb[3 * (y * img.width + x) + 1];
    top /= img.width * (img.height / 4);
    bottom /= img.width * (img.height - img.height / 4);
    EXPECT_NEAR(top, 1.0, 1e-4) << backend;  // the sky, seen directly
    EXPECT_GT(bottom, 0.05) << backend;
    EXPECT_LT(bottom, 0.95) << backend;
  }
}

}  // namespace
}  // namespace tessera
