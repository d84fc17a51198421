// MakeNamedMedium and MediumInterface as pbrt-v4 reads them.
#include <gtest/gtest.h>

#include "scene/pbrt_loader.h"
#include "scene/pbrt_media.h"
#include "scene_test_helpers.h"

namespace tessera {
namespace {

const char* kHead = R"(
MakeNamedMedium "fog" "string type" "homogeneous" "float scale" 2 "rgb sigma_a" [ 0.1 0.2 0.3 ] "rgb sigma_s" [ 1 2 3 ] "float g" 0.4
MediumInterface "" "fog"
LookAt 0 0 -5  0 0 0  0 1 0
Camera "perspective"
WorldBegin
)";

const char* kTriangle = "Shape \"trianglemesh\" \"point3 P\" [ 0 0 0 1 0 0 0 1 0 ] \"integer indices\" [ 0 1 2 ]\n";

TEST(PbrtMedia, HomogeneousParametersAndTheCameraMedium) {
  SceneDesc d = load_pbrt_string(std::string(kHead) + kTriangle, "<t>", ".");
  ASSERT_EQ(d.media.size(), 1u);
  EXPECT_EQ(d.media[0].sigma_a, Rgb(0.2f, 0.4f, 0.6f));  // scale folded in
  EXPECT_EQ(d.media[0].sigma_s, Rgb(2.f, 4.f, 6.f));
  EXPECT_FLOAT_EQ(d.media[0].g, 0.4f);
  EXPECT_EQ(d.camera_medium, 0);  // the outside medium when Camera appears
  // The interface set before WorldBegin still holds for shapes (pbrt-v4 keeps it).
  EXPECT_EQ(d.meshes[0].media.inside, -1);
  EXPECT_EQ(d.meshes[0].media.outside, 0);
}

TEST(PbrtMedia, InterfacesFollowAttributeBlocksAndOneNameMeansBothSides) {
  SceneDesc d = load_pbrt_string(std::string(kHead) + "AttributeBegin\nMediumInterface \"fog\"\n" + kTriangle +
                                     "AttributeEnd\n" + kTriangle,
                                 "<t>", ".");
  ASSERT_EQ(d.meshes.size(), 2u);
  EXPECT_EQ(d.meshes[0].media.inside, 0);
  EXPECT_EQ(d.meshes[0].media.outside, 0);
  EXPECT_FALSE(is_transition(d.meshes[0].media));
  EXPECT_EQ(d.meshes[1].media.inside, -1);
  EXPECT_EQ(d.meshes[1].media.outside, 0);
}

TEST(PbrtMedia, DefaultsAndPresetsArepbrtV4s) {
  SceneDesc d = load_pbrt_string(R"(
MakeNamedMedium "a" "string type" "homogeneous"
MakeNamedMedium "milk" "string type" "homogeneous" "string preset" "Wholemilk" "float scale" 10
LookAt 0 0 -5  0 0 0  0 1 0
Camera "perspective"
WorldBegin
)" + std::string(kTriangle), "<t>", ".");
  ASSERT_EQ(d.media.size(), 2u);
  EXPECT_EQ(d.media[0].sigma_a, Rgb(1.f));
  EXPECT_EQ(d.media[0].sigma_s, Rgb(1.f));
  EXPECT_EQ(d.media[0].g, 0.f);
  EXPECT_EQ(d.camera_medium, -1);
  Rgb a, s;
  ASSERT_TRUE(medium_preset("Wholemilk", &a, &s));
  EXPECT_EQ(d.media[1].sigma_a, a * 10.f);
  EXPECT_EQ(d.media[1].sigma_s, s * 10.f);
}

TEST(PbrtMedia, UniformGridKeepsItsDensitiesBoxAndTransform) {
  SceneDesc d = load_pbrt_string(R"(
LookAt 0 0 -5  0 0 0  0 1 0
Camera "perspective"
WorldBegin
AttributeBegin
Translate 10 0 0
MakeNamedMedium "smoke" "string type" "uniformgrid" "integer nx" 2 "integer ny" 1 "integer nz" 1
  "float density" [ 0.5 3 ] "point3 p0" [ -1 -1 -1 ] "point3 p1" [ 1 1 1 ] "rgb sigma_s" [ 2 2 2 ]
AttributeEnd
MediumInterface "smoke" ""
)" + std::string(kTriangle), "<t>", ".");
  ASSERT_EQ(d.media.size(), 1u);
  ASSERT_EQ(d.grids.size(), 1u);
  EXPECT_EQ(d.media[0].grid, 0);
  EXPECT_EQ(d.media[0].sigma_s, Rgb(2.f));
  const GridDesc& g = d.grids[0];
  EXPECT_EQ(g.density.nx, 2);
  EXPECT_EQ(g.density.ny, 1);
  const SparseGridView v = sparse_grid_view(g.density);
  EXPECT_EQ(lattice_value(v, 0, 0, 0), 0.5f);
  EXPECT_EQ(lattice_value(v, 1, 0, 0), 3.f);
  EXPECT_FLOAT_EQ(g.density.max_value, 3.f);
  // The box sits where the CTM put it: world (10, 0, 0) is the medium's
  // origin, between the two voxel centres (lattice x 0.5).
  const Vec3 centre = Vec3(g.density.lattice_from_world * Vec4(Vec3(10.f, 0.f, 0.f) - Vec3(d.render_origin), 1.f));
  EXPECT_NEAR(centre.x, 0.5f, 1e-5f);
  EXPECT_NEAR(centre.y, 0.f, 1e-5f);
  EXPECT_NEAR(centre.z, 0.f, 1e-5f);
  // The box p0..p1 in lattice coordinates.
  EXPECT_EQ(g.majorants.lo, Vec3(-0.5f));
  EXPECT_EQ(g.majorants.hi, Vec3(1.5f, 0.5f, 0.5f));
  EXPECT_EQ(d.meshes[0].media.inside, 0);
}

TEST(PbrtMedia, RgbGridReadsItsVoxelsAndBoundsEveryWavelength) {
  SceneDesc d = load_pbrt_string(R"(
LookAt 0 0 -5  0 0 0  0 1 0
Camera "perspective"
WorldBegin
MakeNamedMedium "smoke" "string type" "rgbgrid" "integer nx" 2 "float scale" 3
  "rgb sigma_a" [ 0.1 0.2 0.3  1 0 0 ] "rgb Le" [ 0 0 0  5 4 3 ] "float Lescale" 2
MediumInterface "smoke" ""
)" + std::string(kTriangle), "<t>", ".");
  ASSERT_EQ(d.grids.size(), 1u);
  const GridDesc& g = d.grids[0];
  EXPECT_EQ(g.rgb, 1);
  EXPECT_EQ(g.rgb_scale, 3.f);
  EXPECT_EQ(g.rgb_le_scale, 2.f);
  EXPECT_EQ(lattice_value(sparse_grid_view(g.rgb_sigma_a[1]), 0, 0, 0), 0.2f);
  EXPECT_EQ(lattice_value(sparse_grid_view(g.rgb_le[0]), 1, 0, 0), 5.f);
  EXPECT_EQ(g.rgb_sigma_s[0].nx, 0);  // not given: 1 everywhere
  // Every cell bounds scale * (2 max(sigma_a) + 1): here 3 * (2 * 1 + 1) where the red voxel reaches.
  Float most = 0.f;
  for (Float c : g.majorants.max_density) most = std::max(most, c);
  EXPECT_FLOAT_EQ(most, 9.f);
  EXPECT_EQ(d.media[0].grid_emits, 1);
  const std::string e = test::load_error("WorldBegin\nMakeNamedMedium \"m\" \"string type\" \"rgbgrid\" \"integer nx\" 2 "
                                         "\"rgb sigma_s\" [ 1 1 1 ]\n");
  EXPECT_NE(e.find("bad.pbrt:2"), std::string::npos) << e;
  EXPECT_NE(e.find("nx*ny*nz = 2"), std::string::npos) << e;
}

TEST(PbrtMedia, AMediumMayBeDefinedAfterItsUseAsInPbrtV4) {
  SceneDesc d = load_pbrt_string(std::string(R"(
MediumInterface "" "late"
LookAt 0 0 -5  0 0 0  0 1 0
Camera "perspective"
WorldBegin
MakeNamedMedium "early" "string type" "homogeneous"
MediumInterface "late" "early"
)") + kTriangle + "MakeNamedMedium \"late\" \"string type\" \"homogeneous\" \"rgb sigma_s\" [ 2 2 2 ]\n",
                                 "<t>", ".");
  ASSERT_EQ(d.media.size(), 2u);
  EXPECT_EQ(d.camera_medium, 1);
  EXPECT_EQ(d.meshes[0].media.inside, 1);
  EXPECT_EQ(d.meshes[0].media.outside, 0);
  EXPECT_EQ(d.media[1].sigma_s, Rgb(2.f));
}

TEST(PbrtMedia, AreaLightsOnInterfaceShapesAreIgnoredAsInPbrtV4) {
  SceneDesc d = load_pbrt_string(std::string(kHead) + "AttributeBegin\nMaterial \"interface\"\n"
                                 "AreaLightSource \"diffuse\" \"rgb L\" [ 1 1 1 ]\n" + kTriangle + "AttributeEnd\n" + kTriangle,
                                 "<t>", ".");
  EXPECT_EQ(d.meshes[0].area_light, -1);
  bool warned = false;
  for (const std::string& w : d.warnings) warned |= w.find("area light on a shape with the \"interface\"") != std::string::npos;
  EXPECT_TRUE(warned);
}

void expect_error(const std::string& text, const std::string& needle) {
  try {
    load_pbrt_string(text, "scene.pbrt", ".");
    ADD_FAILURE() << "no error for: " << text;
  } catch (const SceneError& e) {
    EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
    EXPECT_EQ(std::string(e.what()).rfind("scene.pbrt:", 0), 0u) << e.what();
  }
}

TEST(PbrtMedia, BadMediaAreOneLineErrors) {
  const std::string world = "WorldBegin\n" + std::string(kTriangle);
  expect_error("MediumInterface \"nowhere\" \"\"\n" + world, "unknown medium \"nowhere\"");
  expect_error(std::string("WorldBegin\nMediumInterface \"\" \"nowhere\"\n") + kTriangle, "scene.pbrt:2: unknown medium");
  expect_error("MakeNamedMedium \"m\" \"float scale\" 1\n" + world, "needs \"string type\"");
  expect_error("MakeNamedMedium \"m\" \"string type\" \"plasma\"\n" + world, "unknown medium type \"plasma\"");
  expect_error("MakeNamedMedium \"m\" \"string type\" \"homogeneous\" \"rgb sigma_a\" [ -1 0 0 ]\n" + world,
               "must be finite and not negative");
  expect_error("MakeNamedMedium \"m\" \"string type\" \"homogeneous\" \"float scale\" -2\n" + world, "scale");
  expect_error("MakeNamedMedium \"m\" \"string type\" \"uniformgrid\" \"integer nx\" 2 \"float density\" [ 1 ]\n" + world,
               "1 density values; nx*ny*nz = 2");
  expect_error("MakeNamedMedium \"m\" \"string type\" \"uniformgrid\"\n" + world, "needs \"float density\"");
  expect_error("MakeNamedMedium \"m\" \"string type\" \"uniformgrid\" \"float density\" [ -1 ]\n" + world,
               "densities must be finite");
  expect_error("MakeNamedMedium \"m\" \"string type\" \"uniformgrid\" \"float density\" [ 1 ] "
               "\"point3 p0\" [ 1 1 1 ] \"point3 p1\" [ 0 2 2 ]\n" + world, "p0 < p1");
}

}  // namespace
}  // namespace tessera
