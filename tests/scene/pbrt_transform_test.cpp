// Transform directives, graphics-state blocks, Include and object instancing.
#include "scene_test_helpers.h"
#include "scene/object_instances.h"

namespace tessera {
namespace {

using test::kTriangle;
using test::load_world;

TEST(PbrtTransform, TranslateThenScaleAppliesScaleFirst) {
  SceneDesc s = load_world(std::string("Translate 1 2 3\nScale 2 2 2\n") + kTriangle);
  ASSERT_EQ(s.meshes.size(), 1u);
  EXPECT_VEC3_NEAR(s.meshes[0].p[1], Vec3(3, 2, 3), 1e-6f);
  EXPECT_VEC3_NEAR(s.meshes[0].p[2], Vec3(1, 4, 3), 1e-6f);
  EXPECT_FALSE(s.meshes[0].flip_normals);
}

TEST(PbrtTransform, RotateIsDegreesAboutAxis) {
  SceneDesc s = load_world(std::string("Rotate 90 0 0 1\n") + kTriangle);
  EXPECT_VEC3_NEAR(s.meshes[0].p[1], Vec3(0, 1, 0), 1e-6f);
  EXPECT_VEC3_NEAR(s.meshes[0].p[2], Vec3(-1, 0, 0), 1e-6f);
}

TEST(PbrtTransform, TransformTakesColumnsAsWritten) {
  SceneDesc s = load_world(std::string("Transform [ 1 0 0 0  0 1 0 0  0 0 1 0  5 6 7 1 ]\n") + kTriangle);
  EXPECT_VEC3_NEAR(s.meshes[0].p[0], Vec3(5, 6, 7), 1e-6f);
  // Transform replaces; ConcatTransform post-multiplies.
  s = load_world(std::string("Translate 100 0 0\nTransform [ 2 0 0 0  0 1 0 0  0 0 1 0  0 0 0 1 ]\n") + kTriangle);
  EXPECT_VEC3_NEAR(s.meshes[0].p[1], Vec3(2, 0, 0), 1e-6f);
  s = load_world(std::string("Translate 1 0 0\nConcatTransform [ 2 0 0 0  0 1 0 0  0 0 1 0  0 0 3 1 ]\n") + kTriangle);
  EXPECT_VEC3_NEAR(s.meshes[0].p[1], Vec3(3, 0, 3), 1e-6f);
}

TEST(PbrtTransform, IdentityResets) {
  SceneDesc s = load_world(std::string("Translate 1 2 3\nIdentity\n") + kTriangle);
  EXPECT_VEC3_NEAR(s.meshes[0].p[0], Vec3(0, 0, 0), 1e-6f);
}

TEST(PbrtTransform, LookAtGivesWorldFromCamera) {
  SceneDesc s = load_pbrt_string("LookAt 0 0 5  0 0 0  0 1 0\nCamera \"perspective\" \"float fov\" [ 40 ]\nWorldBegin\n" +
                                     std::string(kTriangle),
                                 "t.pbrt", ".");
  const Mat4& m = s.camera.world_from_camera;
  EXPECT_VEC3_NEAR(Vec3(m * Vec4(0, 0, 0, 1)) + Vec3(s.render_origin), Vec3(0, 0, 5), 1e-5f);
  EXPECT_VEC3_NEAR(Vec3(m * Vec4(0, 0, 0, 1)), Vec3(0.f), 1e-6f);  // render space: the camera at the origin
  EXPECT_VEC3_NEAR(Vec3(m * Vec4(0, 0, 1, 0)), Vec3(0, 0, -1), 1e-6f);  // forward
  EXPECT_VEC3_NEAR(Vec3(m * Vec4(0, 1, 0, 0)), Vec3(0, 1, 0), 1e-6f);   // up
  EXPECT_VEC3_NEAR(Vec3(m * Vec4(1, 0, 0, 0)), Vec3(-1, 0, 0), 1e-6f);  // right = up x forward
  EXPECT_FLOAT_EQ(s.camera.fov_degrees, 40.f);
  EXPECT_GT(glm::determinant(m), 0.f);
  EXPECT_EQ(s.camera.where, "t.pbrt:2");
}

TEST(PbrtTransform, ScaleBeforeLookAtMirrorsCamera) {
  SceneDesc s = load_pbrt_string("Scale -1 1 1\nLookAt 0 0 5  0 0 0  0 1 0\nCamera \"perspective\"\nWorldBegin\n" +
                                     std::string(kTriangle),
                                 "t.pbrt", ".");
  const Mat4& m = s.camera.world_from_camera;
  EXPECT_LT(glm::determinant(m), 0.f);
  EXPECT_VEC3_NEAR(Vec3(m * Vec4(1, 0, 0, 0)), Vec3(1, 0, 0), 1e-6f);  // image x mirrored
  EXPECT_VEC3_NEAR(Vec3(m * Vec4(0, 0, 1, 0)), Vec3(0, 0, -1), 1e-6f);
  EXPECT_FLOAT_EQ(s.camera.fov_degrees, 90.f);
  // The world CTM starts afresh: shapes are not mirrored.
  EXPECT_FALSE(s.meshes[0].flip_normals);
}

TEST(PbrtTransform, MirroringShapeTransformSetsFlipNormals) {
  SceneDesc s = load_world(std::string("Scale -1 1 1\n") + kTriangle);
  EXPECT_TRUE(s.meshes[0].flip_normals);
  // pbrt-v4 flips the world-space cross product back: the normal stays +z.
  EXPECT_VEC3_NEAR(test::geometric_normal(s.meshes[0], 0), Vec3(0, 0, 1), 1e-6f);
}

TEST(PbrtTransform, ReverseOrientationFlipsAndCancelsWithMirror) {
  SceneDesc s = load_world(std::string("ReverseOrientation\n") + kTriangle);
  EXPECT_TRUE(s.meshes[0].flip_normals);
  EXPECT_VEC3_NEAR(test::geometric_normal(s.meshes[0], 0), Vec3(0, 0, -1), 1e-6f);
  s = load_world(std::string("ReverseOrientation\nScale 1 -1 1\n") + kTriangle);
  EXPECT_FALSE(s.meshes[0].flip_normals);
}

TEST(PbrtTransform, AttributeBlockRestoresState) {
  SceneDesc s = load_world(std::string("AttributeBegin\nTranslate 1 0 0\nReverseOrientation\n") +
                           "Material \"conductor\"\n" + kTriangle + "AttributeEnd\n" + kTriangle);
  ASSERT_EQ(s.meshes.size(), 2u);
  EXPECT_VEC3_NEAR(s.meshes[0].p[0], Vec3(1, 0, 0), 1e-6f);
  EXPECT_TRUE(s.meshes[0].flip_normals);
  EXPECT_EQ(s.materials[s.meshes[0].material].type, MaterialType::Conductor);
  EXPECT_VEC3_NEAR(s.meshes[1].p[0], Vec3(0, 0, 0), 1e-6f);
  EXPECT_FALSE(s.meshes[1].flip_normals);
  EXPECT_EQ(s.meshes[1].material, 0);
}

TEST(PbrtTransform, LegacyTransformBlockRestoresOnlyTransform) {
  SceneDesc s = load_world(std::string("TransformBegin\nTranslate 1 0 0\nMaterial \"conductor\"\nTransformEnd\n") + kTriangle);
  EXPECT_VEC3_NEAR(s.meshes[0].p[0], Vec3(0, 0, 0), 1e-6f);
  EXPECT_EQ(s.materials[s.meshes[0].material].type, MaterialType::Conductor);
  ASSERT_FALSE(s.warnings.empty());
  EXPECT_NE(s.warnings[0].find("test.pbrt:2"), std::string::npos);
}

TEST(PbrtTransform, NamedCoordinateSystems) {
  SceneDesc s = load_pbrt_string(
      "LookAt 1 2 3  0 0 0  0 1 0\nCamera \"perspective\"\nWorldBegin\nTranslate 7 0 0\nCoordinateSystem \"seven\"\n"
      "Identity\nCoordSysTransform \"camera\"\n" + std::string(kTriangle) + "CoordSysTransform \"seven\"\n" + kTriangle,
      "t.pbrt", ".");
  ASSERT_EQ(s.meshes.size(), 2u);
  EXPECT_VEC3_NEAR(s.meshes[0].p[0] + Vec3(s.render_origin), Vec3(1, 2, 3), 1e-5f);  // camera origin
  EXPECT_VEC3_NEAR(s.meshes[1].p[0] + Vec3(s.render_origin), Vec3(7, 0, 0), 1e-6f);
  EXPECT_VEC3_NEAR(Vec3(s.render_origin), Vec3(1, 2, 3), 1e-6f);
}

TEST(PbrtTransform, IncludeIsRelativeToIncludingFileAndKeepsState) {
  test::TempDir dir;
  dir.write("parts/box.pbrt", std::string("# included\n") + kTriangle);
  dir.write("parts/nested.pbrt", "Include \"box.pbrt\"\n");
  dir.write("scene.pbrt", "WorldBegin\nTranslate 0 0 2\nInclude \"parts/nested.pbrt\"\nImport \"parts/box.pbrt\"\n");
  SceneDesc s = load_pbrt_file(dir.file("scene.pbrt"));
  ASSERT_EQ(s.meshes.size(), 2u);
  EXPECT_VEC3_NEAR(s.meshes[0].p[0], Vec3(0, 0, 2), 1e-6f);
  EXPECT_NE(s.meshes[0].where.find("box.pbrt:2"), std::string::npos);
}

TEST(PbrtTransform, ObjectInstancesPlaceTheDefinitionByTheirTransform) {
  SceneDesc s = load_world(std::string("ObjectBegin \"tri\"\nTranslate 0 0 1\n") + kTriangle +
                           "ObjectEnd\nTranslate 10 0 0\nObjectInstance \"tri\"\nScale -1 1 1\nObjectInstance \"tri\"\n");
  EXPECT_TRUE(s.meshes.empty());  // the definition itself is not rendered
  ASSERT_EQ(s.objects.size(), 1u);
  ASSERT_EQ(s.instances.size(), 2u);  // stored once, placed twice
  const std::vector<MeshDesc> first = placed_meshes(s.objects[0], s.instances[0]);
  const std::vector<MeshDesc> second = placed_meshes(s.objects[0], s.instances[1]);
  EXPECT_VEC3_NEAR(first[0].p[1], Vec3(11, 0, 1), 1e-6f);
  EXPECT_FALSE(first[0].flip_normals);
  EXPECT_VEC3_NEAR(second[0].p[1], Vec3(9, 0, 1), 1e-6f);
  EXPECT_TRUE(second[0].flip_normals);
  EXPECT_EQ(second[0].where, "test.pbrt:9");
}

// An object instanced once is placed as ordinary meshes (nothing to share),
// as is an instance whose transform is singular (it flattens the object).
TEST(PbrtTransform, ObjectsUsedOnceAndSingularInstancesAreFlattened) {
  SceneDesc once = load_world(std::string("ObjectBegin \"tri\"\n") + kTriangle +
                              "ObjectEnd\nTranslate 10 0 0\nObjectInstance \"tri\"\n");
  EXPECT_TRUE(once.objects.empty());
  EXPECT_TRUE(once.instances.empty());
  ASSERT_EQ(once.meshes.size(), 1u);
  EXPECT_EQ(once.meshes[0].where, "test.pbrt:6");
  SceneDesc flat = load_world(std::string("ObjectBegin \"tri\"\n") + kTriangle +
                              "ObjectEnd\nObjectInstance \"tri\"\nScale 1 1 0\nObjectInstance \"tri\"\n");
  EXPECT_TRUE(flat.objects.empty());  // the singular one is flattened; the other is then the only instance
  EXPECT_TRUE(flat.instances.empty());
  ASSERT_EQ(flat.meshes.size(), 2u);
  for (const MeshDesc& m : flat.meshes) EXPECT_EQ(m.p.size(), 3u);
}

// A redefined object is a new one: instances made before keep the old shapes.
TEST(PbrtTransform, RedefiningAnObjectKeepsEarlierInstances) {
  const std::string tri = kTriangle;
  SceneDesc s = load_world("ObjectBegin \"o\"\n" + tri + "ObjectEnd\nObjectInstance \"o\"\nObjectInstance \"o\"\n" +
                           "ObjectBegin \"o\"\n" + tri + tri + "ObjectEnd\nObjectInstance \"o\"\nObjectInstance \"o\"\n");
  ASSERT_EQ(s.objects.size(), 2u);
  ASSERT_EQ(s.instances.size(), 4u);
  EXPECT_EQ(s.objects[s.instances[0].object].meshes.size(), 1u);
  EXPECT_EQ(s.objects[s.instances[3].object].meshes.size(), 2u);
}

// Transform numbers are read in double: an object at x = 1000000.3 seen from
// a camera at x = 1000000 sits 0.3 from it in render space (as float,
// 1000000.3 is 1000000.3125).
TEST(PbrtTransform, TransformNumbersKeepDoublePrecision) {
  SceneDesc s = load_pbrt_string(std::string("LookAt 1000000 0 -5  1000000 0 0  0 1 0\nCamera \"perspective\"\n"
                                             "WorldBegin\nTranslate 1000000.3 0 0\n") + kTriangle,
                                 "t.pbrt", ".");
  EXPECT_NEAR(s.meshes[0].p[0].x, 0.3f, 1e-6f);
}

// With the camera away from the origin (render space moves the world), an
// instance, an absolute Transform and the "world" coordinate system still
// land where the file puts them in its world.
TEST(PbrtTransform, RenderSpaceKeepsWorldPlacement) {
  SceneDesc s = load_pbrt_string(std::string("LookAt 3 4 5  0 0 0  0 1 0\nCamera \"perspective\"\nWorldBegin\n"
                                             "ObjectBegin \"tri\"\nTranslate 0 0 1\n") +
                                     kTriangle + "ObjectEnd\nTranslate 10 0 0\nObjectInstance \"tri\"\n" +
                                     "Transform [ 1 0 0 0  0 1 0 0  0 0 1 0  0 7 0 1 ]\n" + kTriangle +
                                     "CoordSysTransform \"world\"\n" + kTriangle,
                                 "t.pbrt", ".");
  ASSERT_EQ(s.meshes.size(), 3u);
  const Vec3 origin(s.render_origin);
  EXPECT_VEC3_NEAR(origin, Vec3(3, 4, 5), 1e-5f);
  EXPECT_VEC3_NEAR(s.meshes[0].p[1] + origin, Vec3(11, 0, 1), 1e-5f);  // instance: Translate 10, then its own 0 0 1
  EXPECT_VEC3_NEAR(s.meshes[1].p[0] + origin, Vec3(0, 7, 0), 1e-5f);   // absolute Transform in world space
  EXPECT_VEC3_NEAR(s.meshes[2].p[0] + origin, Vec3(0, 0, 0), 1e-5f);   // the world's own frame
}

}  // namespace
}  // namespace tessera

namespace tessera {
namespace {

TEST(PbrtMotion, ActiveTransformMovesOnlyTheEndOrStartTransform) {
  SceneDesc s = test::load_world(std::string("Translate 1 0 0\nActiveTransform EndTime\nTranslate 0 5 0\n"
                                             "ActiveTransform StartTime\nTranslate 0 0 2\nActiveTransform All\n") +
                                 test::kTriangle + "AttributeBegin\nActiveTransform StartTime\nAttributeEnd\n" + test::kTriangle);
  const MeshDesc& m = s.meshes[0];
  ASSERT_EQ(m.p_end.size(), m.p.size());
  // Start: (1, 0, 2) + p; end: (1, 5, 0) + p.
  EXPECT_EQ(m.p[0] - m.p_end[0], Vec3(0.f, -5.f, 2.f));
  // AttributeEnd restores the active transforms; the second shape still moves.
  EXPECT_EQ(s.meshes[1].p[0] - s.meshes[1].p_end[0], Vec3(0.f, -5.f, 2.f));
}

TEST(PbrtMotion, StaticScenesHaveNoEndPositions) {
  SceneDesc s = test::load_world(std::string("Translate 1 2 3\n") + test::kTriangle);
  EXPECT_TRUE(s.meshes[0].p_end.empty());
}

TEST(PbrtMotion, BadMotionDirectivesAreErrors) {
  auto fails = [](const std::string& text, const std::string& needle) {
    try {
      load_pbrt_string(text, "m.pbrt", ".");
      ADD_FAILURE() << text;
    } catch (const SceneError& e) {
      EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
    }
  };
  fails(std::string("WorldBegin\nActiveTransform Sometimes\n") + test::kTriangle, "ActiveTransform takes All");
  fails(std::string("TransformTimes 1 0\nWorldBegin\n") + test::kTriangle, "start time below its end time");
  fails(std::string("WorldBegin\nTransformTimes 0 1\n") + test::kTriangle, "not allowed after WorldBegin");
  fails(std::string("WorldBegin\nActiveTransform EndTime\nScale 1e30 1e30 1e30\nScale 1e30 1e30 1e30\n") +
            test::kTriangle,
        "at the end of the motion");
}

// A last row of zeros maps every point to infinity (pbrt-v4 divides by w):
// refused with the directive's line, not a shape moved onto the camera.
TEST(PbrtTransform, ALastRowOfZerosIsRefused) {
  for (const char* d : {"Transform", "ConcatTransform"}) {
    const std::string e = test::load_error(std::string("WorldBegin\nAttributeBegin\n") + d +
                                           " [ 1 0 0 0  0 1 0 0  0 0 1 0  5 5 5 0 ]\n" + kTriangle + "AttributeEnd\n");
    EXPECT_NE(e.find(":3: " + std::string(d) + ": the matrix's last row"), std::string::npos) << e;
  }
}

}  // namespace
}  // namespace tessera
