// Malformed input: every case throws SceneError with "file:line: problem".
#include <ImfRgbaFile.h>

#include "scene_test_helpers.h"

namespace tessera {
namespace {

using test::load_error;

// World-block text starts at line 2 of bad.pbrt.
std::string world_error(const std::string& body, const std::string& dir = ".") {
  return load_error("WorldBegin\n" + body, dir);
}

#define EXPECT_ERROR_CONTAINS(message, part) EXPECT_NE((message).find(part), std::string::npos) << (message)

TEST(PbrtErrors, MalformedNumbers) {
  EXPECT_ERROR_CONTAINS(world_error("Translate 1 x 3\n"), "bad.pbrt:2: malformed number 'x'");
  EXPECT_ERROR_CONTAINS(world_error("\nShape \"sphere\" \"float radius\" [ 1.2.3 ]\n"), "bad.pbrt:3: malformed number '1.2.3'");
  EXPECT_ERROR_CONTAINS(world_error("Shape \"sphere\" \"integer radius\" [ 1.5 ]\n"), "bad.pbrt:2: non-integer");
}

TEST(PbrtErrors, NanAndInfCoordinates) {
  EXPECT_ERROR_CONTAINS(world_error("Shape \"trianglemesh\" \"point3 P\" [ 0 0 0 1 nan 0 0 1 0 ]\n"), "bad.pbrt:2: malformed number 'nan'");
  EXPECT_ERROR_CONTAINS(world_error("Shape \"trianglemesh\" \"point3 P\" [ 0 0 0 1 -inf 0 0 1 0 ]\n"), "bad.pbrt:2:");
  EXPECT_ERROR_CONTAINS(world_error("\n\nTranslate 1e999 0 0\n"), "bad.pbrt:4: number out of range '1e999'");
  EXPECT_ERROR_CONTAINS(world_error("Shape \"trianglemesh\" \"point3 P\" [ 0 0 0 1 1e39 0 0 1 0 ]\n"), "bad.pbrt:2: number out of range");
  // Finite inputs that overflow once transformed.
  EXPECT_ERROR_CONTAINS(world_error("Scale 1e30 1e30 1e30\nShape \"trianglemesh\" \"point3 P\" [ 0 0 0 1e30 0 0 0 1 0 ]\n"),
                        "bad.pbrt:3: non-finite vertex coordinates");
}

TEST(PbrtErrors, UnterminatedStringAndArray) {
  EXPECT_ERROR_CONTAINS(world_error("Shape \"sphere\n"), "bad.pbrt:2: unterminated string");
  EXPECT_ERROR_CONTAINS(world_error("\nShape \"trianglemesh\" \"point3 P\" [ 0 0 0 1 0 0 0 1 0\nAttributeBegin\n"),
                        "bad.pbrt:3: unterminated array");
  EXPECT_ERROR_CONTAINS(world_error("Shape \"trianglemesh\" \"point3 P\" [ 0 0 0 1 0 0 0 1 0\n"), "bad.pbrt:2: unterminated array");
}

TEST(PbrtErrors, WrongArity) {
  EXPECT_ERROR_CONTAINS(world_error("Shape \"trianglemesh\"\n \"point3 P\" [ 0 0 0 1 0 0 0 1 ]\n"),
                        "bad.pbrt:3: \"point3 P\" needs a multiple of 3 values, got 8");
  EXPECT_ERROR_CONTAINS(world_error("Shape \"trianglemesh\" \"point3 P\" [ 0 0 0 1 0 0 0 1 0 1 1 0 ] \"integer indices\" [ 0 1 2 3 ]\n"),
                        "bad.pbrt:2: trianglemesh \"indices\" count 4 is not a multiple of 3");
  EXPECT_ERROR_CONTAINS(world_error("Shape \"trianglemesh\" \"point3 P\" [ 0 0 0 1 0 0 0 1 0 1 1 0 ]\n"), "bad.pbrt:2:");
  EXPECT_ERROR_CONTAINS(world_error("LightSource \"point\" \"rgb I\" [ 1 1 ]\n"), "bad.pbrt:2: \"rgb I\" needs a multiple of 3");
  EXPECT_ERROR_CONTAINS(world_error("Rotate 90 0 1\n"), "bad.pbrt:2: Rotate needs 4 numbers, got 3");
  EXPECT_ERROR_CONTAINS(world_error("Shape \"sphere\" \"colour radius\" 1\n"), "bad.pbrt:2: unknown parameter type 'colour'");
}

TEST(PbrtErrors, IndexOutOfRange) {
  EXPECT_ERROR_CONTAINS(world_error("\nShape \"trianglemesh\" \"point3 P\" [ 0 0 0 1 0 0 0 1 0 ] \"integer indices\" [ 0 1 3 ]\n"),
                        "bad.pbrt:3: trianglemesh index 3 out of range (3 vertices)");
  EXPECT_ERROR_CONTAINS(world_error("Shape \"bilinearmesh\" \"point3 P\" [ 0 0 0 1 0 0 0 1 0 1 1 0 ] \"integer indices\" [ 0 1 2 -1 ]\n"),
                        "bad.pbrt:2: bilinearmesh index -1 out of range");
}

TEST(PbrtErrors, MissingFilesAreNamed) {
  test::TempDir dir;
  std::string e = world_error("Include \"nowhere/scene.pbrt\"\n", dir.path());
  EXPECT_ERROR_CONTAINS(e, "bad.pbrt:2: Include file '");
  EXPECT_ERROR_CONTAINS(e, "nowhere/scene.pbrt");
  e = world_error("\nShape \"plymesh\" \"string filename\" \"bunny.ply\"\n", dir.path());
  EXPECT_ERROR_CONTAINS(e, "bad.pbrt:3: plymesh file '");
  EXPECT_ERROR_CONTAINS(e, "bunny.ply' not found");
  e = world_error("Texture \"t\" \"spectrum\" \"imagemap\" \"string filename\" \"wood.png\"\n", dir.path());
  EXPECT_ERROR_CONTAINS(e, "bad.pbrt:2: image file '");
  EXPECT_ERROR_CONTAINS(e, "wood.png' not found");
  // A folder given as the scene (found by the cli fuzz target: it read as an empty scene).
  EXPECT_ERROR_CONTAINS(test::load_file_error(dir.path()), ":1: a folder, not a scene file");
  // A file that exists but is not a PLY.
  dir.write("junk.ply", "not a ply file\n");
  EXPECT_ERROR_CONTAINS(world_error("Shape \"plymesh\" \"string filename\" \"junk.ply\"\n", dir.path()), "bad.pbrt:2: cannot read PLY");
  // Errors inside an included file name that file.
  dir.write("inc.pbrt", "\n\nShape \"sphere\" \"float radius\" [ 1 \n");
  EXPECT_ERROR_CONTAINS(world_error("Include \"inc.pbrt\"\n", dir.path()), "inc.pbrt:3: unterminated array");
  try {
    load_pbrt_file(dir.file("no-such-scene.pbrt"));
    ADD_FAILURE() << "no error";
  } catch (const SceneError& err) {
    EXPECT_ERROR_CONTAINS(std::string(err.what()), "no-such-scene.pbrt:1: cannot open");
  }
}

TEST(PbrtErrors, UnbalancedBlocks) {
  EXPECT_ERROR_CONTAINS(world_error("AttributeBegin\nAttributeEnd\nAttributeEnd\n"),
                        "bad.pbrt:4: AttributeEnd without matching AttributeBegin");
  EXPECT_ERROR_CONTAINS(world_error("ObjectEnd\n"), "bad.pbrt:2: ObjectEnd without matching ObjectBegin");
  EXPECT_ERROR_CONTAINS(world_error("ObjectInstance \"ghost\"\n"), "bad.pbrt:2: unknown object \"ghost\"");
}

TEST(PbrtErrors, UnknownNamedMaterialAndTexture) {
  EXPECT_ERROR_CONTAINS(world_error("NamedMaterial \"gold\"\n"), "bad.pbrt:2: unknown named material \"gold\"");
  EXPECT_ERROR_CONTAINS(world_error("\nMaterial \"diffuse\" \"texture reflectance\" \"wood\"\n"), "bad.pbrt:3: unknown texture \"wood\"");
  EXPECT_ERROR_CONTAINS(world_error("Material \"mix\" \"string materials\" [ \"a\" \"b\" ]\n"), "bad.pbrt:2: unknown named material \"a\"");
  EXPECT_ERROR_CONTAINS(world_error("Material \"conductor\" \"spectrum eta\" \"metal-Unobtainium-eta\"\n"),
                        "bad.pbrt:2: unknown named spectrum \"metal-Unobtainium-eta\"");
}

TEST(PbrtErrors, EmptySceneReportsLastLine) {
  EXPECT_ERROR_CONTAINS(load_error("Camera \"perspective\"\nWorldBegin\nAttributeBegin\nAttributeEnd\n"),
                        "bad.pbrt:4: empty scene");
  EXPECT_ERROR_CONTAINS(load_error("WorldBegin\nMaterial \"diffuse\"\n# nothing here\n"), "bad.pbrt:3: empty scene");
}

TEST(PbrtErrors, MissingWorldBegin) {
  EXPECT_ERROR_CONTAINS(load_error("Camera \"perspective\"\nFilm \"rgb\"\n"), "bad.pbrt:2: missing WorldBegin");
  EXPECT_ERROR_CONTAINS(load_error("Camera \"perspective\"\n\nShape \"sphere\"\n"), "bad.pbrt:3: 'Shape' before WorldBegin");
  EXPECT_ERROR_CONTAINS(world_error("Camera \"perspective\"\n"), "bad.pbrt:2: 'Camera' is not allowed after WorldBegin");
}

TEST(PbrtErrors, InfiniteLightArguments) {
  test::TempDir dir;
  Imf::Rgba pixels[4 * 2];
  for (Imf::Rgba& p : pixels) p = Imf::Rgba(1.f, 1.f, 1.f, 1.f);
  {
    Imf::RgbaOutputFile out(dir.file("wide.exr").c_str(), 4, 2, Imf::WRITE_RGBA);
    out.setFrameBuffer(pixels, 1, 4);
    out.writePixels(2);
  }
  EXPECT_ERROR_CONTAINS(world_error("LightSource \"infinite\" \"rgb L\" [ 1 1 1 ] \"string filename\" \"wide.exr\"\n", dir.path()),
                        "bad.pbrt:2: infinite light takes either");
  EXPECT_ERROR_CONTAINS(world_error("\nLightSource \"infinite\" \"string filename\" \"wide.exr\"\n", dir.path()),
                        "bad.pbrt:3: infinite light image");
}

TEST(PbrtErrors, UnknownDirectiveOnlyWarns) {
  SceneDesc s = load_pbrt_string("WorldBegin\nColorSpace \"aces2065-1\"\nFrobnicate [ 1 2 ] \"x\"\n" +
                                     std::string(test::kTriangle),
                                 "ok.pbrt", ".");
  ASSERT_EQ(s.warnings.size(), 2u);
  EXPECT_ERROR_CONTAINS(s.warnings[0], "ok.pbrt:2:");
  EXPECT_ERROR_CONTAINS(s.warnings[1], "ok.pbrt:3: unknown directive 'Frobnicate'");
  EXPECT_EQ(s.meshes.size(), 1u);
}

}  // namespace
}  // namespace tessera
