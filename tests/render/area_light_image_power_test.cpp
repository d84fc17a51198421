// Area lights as pbrt-v4's DiffuseAreaLight: an image over the shape's uv
// ("filename"), and "power" given to each shape pbrt-v4 would make (each
// triangle of a triangle mesh, each bilinear patch, a whole quadric).
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>

#include "render/image_output.h"
#include "render_helpers.h"

namespace tessera {
namespace {

constexpr double kPiD = 3.14159265358979323846;

// Renders a camera looking straight down at `emitter` (which must fill the
// view: the 10-degree view is 0.88 wide at the origin); returns the film mean.
ImageRgb seen_from_above(const std::string& emitter, int spp = 4) {
  const std::string scene = R"(
LookAt 0 5 0  0 0 0  0 0 1
Camera "perspective" "float fov" [ 10 ]
Film "rgb" "integer xresolution" [ 16 ] "integer yresolution" [ 16 ]
Sampler "independent" "integer pixelsamples" [ )" + std::to_string(spp) + R"( ]
Integrator "path" "integer maxdepth" [ 1 ]
WorldBegin
)" + emitter;
  return film_mean(testing::render_text(scene).film);
}

constexpr const char* kQuadTriangles =
    R"(Shape "trianglemesh" "point3 P" [ -1 0 -1  1 0 -1  1 0 1  -1 0 1 ] "integer indices" [ 0 1 2 0 2 3 ])";

TEST(AreaLightPower, EachShapeEmitsThePowerAsInPbrtV4) {
  // Two-sided, so each shape's radiance is power / (2 pi area).
  const std::string light = R"(AreaLightSource "diffuse" "float power" [ 10 ] "bool twosided" true
)";
  // A triangle mesh: each of its two triangles (area 2) emits 10.
  EXPECT_NEAR(testing::image_mean(seen_from_above(light + kQuadTriangles)), 10 / (2 * kPiD * 2), 1e-5);
  // A bilinear patch (area 4) is one shape.
  EXPECT_NEAR(testing::image_mean(seen_from_above(
                  light + R"(Shape "bilinearmesh" "point3 P" [ -1 0 -1  1 0 -1  -1 0 1  1 0 1 ])")),
              10 / (2 * kPiD * 4), 1e-5);
  // A disk is one shape of pbrt-v4's analytic area (pi r^2), however it is tessellated.
  EXPECT_NEAR(testing::image_mean(seen_from_above("Rotate -90 1 0 0\n" + light + R"(Shape "disk" "float radius" [ 2 ])")),
              10 / (2 * kPiD * kPiD * 4), 1e-5);
  // L multiplies the power (pbrt-v4 normalises only the illuminant, not the RGB).
  EXPECT_NEAR(testing::image_mean(seen_from_above(
                  R"(AreaLightSource "diffuse" "rgb L" [ 3 3 3 ] "float power" [ 10 ] "bool twosided" true
)" + std::string(kQuadTriangles))),
              3 * 10 / (2 * kPiD * 2), 1e-4);
}

class ImageAreaLight : public ::testing::Test {
 protected:
  void write(int w, int h, const std::vector<float>& rgb) { write_exr(path_, ImageRgb{w, h, rgb}, nullptr, {}); }
  std::string light(const std::string& extra = "") const {
    return R"(AreaLightSource "diffuse" "string filename" [ ")" + path_ + "\" ] \"bool twosided\" true " + extra + "\n";
  }
  testing::TempFile file_{"area.exr"};
  const std::string& path_ = file_.path();
};

TEST_F(ImageAreaLight, ShowsItsTexelsOverTheShapesUv) {
  // Left texel red 3, right texel green 2. u runs from -10 to 11 across the
  // quad, so the view's outer columns read the clamped edge texels alone.
  write(2, 1, {3.f, 0.f, 0.f, 0.f, 2.f, 0.f});
  const std::string quad =
      R"(Shape "trianglemesh" "point3 P" [ -1 0 -1  1 0 -1  1 0 1  -1 0 1 ] "integer indices" [ 0 1 2 0 2 3 ]
 "point2 uv" [ -10 0  11 0  11 1  -10 1 ])";
  const ImageRgb img = seen_from_above(light("\"float scale\" [ 2 ]") + quad);
  auto pixel = [&](int x, int y, int c) { return img.rgb[3 * (y * img.width + x) + c]; };
  // Which screen side shows u = -10 is the camera's business: one side is red, the other green.
  const bool red_left = pixel(0, 8, 0) > pixel(15, 8, 0);
  const int red = red_left ? 0 : 15, green = red_left ? 15 : 0;
  for (int y = 0; y < 16; ++y) {
    EXPECT_NEAR(pixel(red, y, 0), 6.f, 1e-4f);
    EXPECT_NEAR(pixel(red, y, 1), 0.f, 1e-4f);
    EXPECT_NEAR(pixel(green, y, 0), 0.f, 1e-4f);
    EXPECT_NEAR(pixel(green, y, 1), 4.f, 1e-4f);
  }
  // With "power", the texels are scaled by power / (mean texel luminance x pi x area x sides).
  const ImageRgb powered = seen_from_above(light("\"float power\" [ 10 ]") + quad);
  const double k_e = 0.5 * (0.2126 * 3 + 0.7152 * 2), scale = 10 / (k_e * kPiD * 2 * 2);
  EXPECT_NEAR(powered.rgb[3 * (8 * 16 + red)], 3 * scale, 1e-4);
  EXPECT_NEAR(powered.rgb[3 * (8 * 16 + green) + 1], 2 * scale, 1e-4);
}

TEST_F(ImageAreaLight, NeeAndBsdfSamplingAgree) {
  // A one-sided emitter facing down onto a diffuse floor, one bright texel:
  // the light sample's radiance must be read where the sample lands.
  write(2, 2, {20.f, 20.f, 20.f, 0.1f, 0.1f, 0.1f, 0.1f, 0.1f, 0.1f, 0.1f, 0.1f, 0.1f});
  const std::string scene = R"(
LookAt 0 3 -4  0 0 0  0 1 0
Camera "perspective" "float fov" [ 40 ]
Film "rgb" "integer xresolution" [ 24 ] "integer yresolution" [ 24 ]
Sampler "independent" "integer pixelsamples" [ 256 ]
Integrator "path" "integer maxdepth" [ 2 ]
WorldBegin
AttributeBegin
AreaLightSource "diffuse" "string filename" [ ")" + path_ + R"(" ]
Shape "trianglemesh" "point3 P" [ -1 1 -1  1 1 -1  1 1 1  -1 1 1 ] "integer indices" [ 0 1 2 0 2 3 ]
  "point2 uv" [ 0 0  1 0  1 1  0 1 ]
AttributeEnd
Material "diffuse" "rgb reflectance" [ 0.5 0.5 0.5 ]
Shape "trianglemesh" "point3 P" [ -4 0 -4  4 0 -4  4 0 4  -4 0 4 ] "integer indices" [ 0 1 2 0 2 3 ]
)";
  RenderOptions nee, bsdf_only;
  bsdf_only.nee = false;
  const double a = testing::image_mean(film_mean(testing::render_text(scene, nee).film));
  const double b = testing::image_mean(film_mean(testing::render_text(scene, bsdf_only).film));
  EXPECT_GT(a, 0.05);
  EXPECT_NEAR(a, b, 0.03 * a);
}

TEST(AreaLightErrors, ImageAndLTogetherAndNonFiniteTexelsAreRefused) {
  const testing::TempFile nan_file("area_nan.exr");
  const std::string& nan_path = nan_file.path();
  write_exr(nan_path, ImageRgb{1, 1, {NAN, 1.f, 1.f}}, nullptr, {});
  auto error = [](const std::string& world) {
    try {
      load_pbrt_string("WorldBegin\n" + world + std::string(kQuadTriangles) + "\n", "bad.pbrt", ".");
    } catch (const SceneError& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  EXPECT_NE(error("AreaLightSource \"diffuse\" \"rgb L\" [ 1 1 1 ] \"string filename\" \"" + nan_path + "\"\n")
                .find("either \"L\" or \"filename\""),
            std::string::npos);
  const std::string e = error("AreaLightSource \"diffuse\" \"string filename\" \"" + nan_path + "\"\n");
  EXPECT_NE(e.find("bad.pbrt:2"), std::string::npos) << e;
  EXPECT_NE(e.find("NaN or infinite texels"), std::string::npos) << e;
  // Environment maps too, as in pbrt-v4.
  EXPECT_NE(error("LightSource \"infinite\" \"string filename\" \"" + nan_path + "\"\n").find("NaN or infinite texels"),
            std::string::npos);
}

}  // namespace
}  // namespace tessera
