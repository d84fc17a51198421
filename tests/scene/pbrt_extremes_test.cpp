// Hostile but well-formed input that the kernels cannot render as written:
// coordinates beyond single-precision ray tracing (vertices, the camera,
// lights), textures nested deeper
// than the kernels' recursion, mixes of mixes deeper than their loop. Each is
// a one-line "file:line: problem" at load, never a crash or a silent default.
#include <string>

#include "scene/pbrt_context.h"
#include "scene_test_helpers.h"

namespace tessera {
namespace {

using test::load_error;

#define EXPECT_ERROR_CONTAINS(message, part) EXPECT_NE((message).find(part), std::string::npos) << (message)

void load_ok(const std::string& text) { load_pbrt_string(text, "ok.pbrt", "."); }

const char* kCamera = "LookAt 0 0 -5  0 0 0  0 1 0\nCamera \"perspective\"\n";

// A chain of `n` spectrum textures, each scaling the one before; the last is "t<n-1>".
std::string texture_chain(int n) {
  std::string s = "Texture \"t0\" \"spectrum\" \"constant\" \"rgb value\" [ 0.5 0.5 0.5 ]\n";
  for (int i = 1; i < n; ++i)
    s += "Texture \"t" + std::to_string(i) + "\" \"spectrum\" \"scale\" \"texture tex\" \"t" + std::to_string(i - 1) +
         "\" \"float scale\" 1\n";
  return s;
}

// A mix of mixes `n` deep; the outermost is "m<n>".
std::string mix_chain(int n) {
  std::string s = "MakeNamedMaterial \"m0\" \"string type\" \"diffuse\"\n";
  for (int i = 1; i <= n; ++i)
    s += "MakeNamedMaterial \"m" + std::to_string(i) + "\" \"string type\" \"mix\" \"string materials\" [ \"m" +
         std::to_string(i - 1) + "\" \"m0\" ]\n";
  return s;
}

TEST(PbrtExtremes, FarCameraIsAnError) {
  EXPECT_ERROR_CONTAINS(load_error("LookAt 0 0 -2e18  0 0 0  0 1 0\nCamera \"perspective\"\nWorldBegin\n"),
                        "bad.pbrt:2: the camera is at (0, 0, -2e+18)");
  EXPECT_NO_THROW(load_ok("LookAt 0 0 -1e17  0 0 0  0 1 0\nCamera \"perspective\"\nWorldBegin\n" + std::string(test::kTriangle)));
}

TEST(PbrtExtremes, FarVerticesAreAnError) {
  const std::string far = std::string(kCamera) + "WorldBegin\n\nShape \"trianglemesh\" \"point3 P\" [ 0 0 0 1e19 0 0 0 1 0 ]\n";
  EXPECT_ERROR_CONTAINS(load_error(far), "bad.pbrt:5: a vertex of the shape is at (1e+19, 0, 0)");
  // Inside an object instance, placed far away.
  const std::string instance = std::string(kCamera) +
                               "WorldBegin\nObjectBegin \"o\"\n" + test::kTriangle + "ObjectEnd\nTranslate 5e18 0 0\n"
                               "ObjectInstance \"o\"\n";
  EXPECT_ERROR_CONTAINS(load_error(instance), "a vertex of the shape is at (5e+18");
  // One of several instances (kept instanced, checked by the object's box).
  const std::string second = std::string(kCamera) + "WorldBegin\nObjectBegin \"o\"\n" + test::kTriangle +
                             "ObjectEnd\nObjectInstance \"o\"\nTranslate 0 -5e18 0\nObjectInstance \"o\"\n";
  EXPECT_ERROR_CONTAINS(load_error(second), "bad.pbrt:9: a vertex of the shape is at (0, -5e+18");
}

// Light paths start at a light's position, where Embree refuses rays past
// 1.8e18; pbrt-v4's falloff overflows to black past 1.8e19.
TEST(PbrtExtremes, FarLightsAreAnError) {
  const std::string world = std::string(kCamera) + "WorldBegin\n";
  EXPECT_ERROR_CONTAINS(load_error(world + "LightSource \"point\" \"rgb I\" [ 1e38 1e38 1e38 ] \"point3 from\" [ 2e19 0 0 ]\n"),
                        "bad.pbrt:4: the light is at (2e+19, 0, 0): beyond +-1e+18");
  EXPECT_ERROR_CONTAINS(load_error(world + "Translate 0 -3e18 0\nLightSource \"spot\"\n"),
                        "bad.pbrt:5: the light is at (0, -3e+18, 0)");
  EXPECT_ERROR_CONTAINS(load_error(world + "Translate 0 0 1.5e18\nLightSource \"goniometric\"\n"),
                        "bad.pbrt:5: the light is at (0, 0, 1.5e+18)");
  EXPECT_ERROR_CONTAINS(load_error(world + "LightSource \"spot\" \"point3 to\" [ 3e38 3e38 3e38 ]\n"),
                        "bad.pbrt:4: the light's direction from \"from\" to \"to\" overflows single precision");
  EXPECT_ERROR_CONTAINS(load_error(world + "LightSource \"point\" \"rgb I\" [ 3e38 1 1 ] \"float power\" [ 1e10 ]\n"),
                        "bad.pbrt:4: the light's emission");
  EXPECT_ERROR_CONTAINS(load_error(world + "AreaLightSource \"diffuse\" \"rgb L\" [ 1e30 1 1 ] \"float scale\" [ 1e30 ]\n"),
                        "bad.pbrt:4: area light \"L\" times \"scale\" is not finite");
  // Finite, but a pixel's sums of it would not be (found by the render fuzz target).
  EXPECT_ERROR_CONTAINS(load_error(world + "AreaLightSource \"diffuse\" \"rgb L\" [ 1e30 1 1 ] \"float scale\" [ 1e8 ]\n"),
                        "bad.pbrt:4: area light \"L\" times \"scale\" is 1e+38, beyond 1e+32");
  EXPECT_ERROR_CONTAINS(load_error(world + "LightSource \"infinite\" \"rgb L\" [ 1 1e34 1 ]\n"),
                        "bad.pbrt:4: the light's radiance (times \"scale\" and \"power\") is 1e+34, beyond 1e+32");
  // Distant and infinite lights have no position; lights within the limits load.
  EXPECT_NO_THROW(load_ok(world + "LightSource \"distant\" \"point3 from\" [ 0 0 -1e19 ]\n" + test::kTriangle));
  EXPECT_NO_THROW(load_ok(world + "LightSource \"point\" \"point3 from\" [ 0 0 -1e18 ]\n" + test::kTriangle));
}

// Integers beyond int's range were converted with undefined behaviour (a huge
// xresolution was then reported as "must be positive").
TEST(PbrtExtremes, IntegersBeyondIntAreAnError) {
  EXPECT_ERROR_CONTAINS(load_error("Film \"rgb\" \"integer xresolution\" [ 4294967296 ]\nWorldBegin\n"),
                        "bad.pbrt:1: integer '4294967296' for \"integer xresolution\" is out of range");
  EXPECT_ERROR_CONTAINS(load_error("WorldBegin\nShape \"trianglemesh\" \"point3 P\" [ 0 0 0 1 0 0 0 1 0 ] "
                                   "\"integer indices\" [ 0 1 -3000000000 ]\n"),
                        "bad.pbrt:2: integer '-3000000000'");
}

TEST(PbrtExtremes, TextureNestingIsBounded) {
  const std::string ok = std::string(kCamera) + "WorldBegin\n" + texture_chain(kMaxTextureNesting) +
                         "Material \"diffuse\" \"texture reflectance\" \"t" + std::to_string(kMaxTextureNesting - 1) +
                         "\"\n" + test::kTriangle;
  EXPECT_NO_THROW(load_ok(ok));
  const std::string deep = std::string(kCamera) + "WorldBegin\n" + texture_chain(kMaxTextureNesting + 1);
  // The chain starts on line 4; texture t64 (the 65th) is on line 68.
  EXPECT_ERROR_CONTAINS(load_error(deep), "bad.pbrt:68: texture nests 65 textures deep; at most 64 are supported");
}

TEST(PbrtExtremes, MixNestingIsBounded) {
  EXPECT_NO_THROW(load_ok(std::string(kCamera) + "WorldBegin\n" + mix_chain(kMaxMixNesting) + "NamedMaterial \"m16\"\n" +
                             test::kTriangle));
  // m17 is on line 4 + 17 = 21.
  EXPECT_ERROR_CONTAINS(load_error(std::string(kCamera) + "WorldBegin\n" + mix_chain(kMaxMixNesting + 1)),
                        "bad.pbrt:21: mix material nests 17 mixes deep; at most 16 are supported");
}

}  // namespace
}  // namespace tessera
