// pbrt-v4's goniometric light (a point light whose intensity is I times a
// grey equal-area image over directions, read with y and z swapped) and its
// projection light (a slide projected through a perspective window).
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>

#include "render/image_output.h"
#include "render_helpers.h"

namespace tessera {
namespace {

// A diffuse plane at y = 0 seen from above; the light is inserted after
// WorldBegin. Returns the film's mean (direct light only).
double plane_radiance(const std::string& light) {
  const std::string scene = R"(
LookAt 0 5 0  0 0 0  0 0 1
Camera "perspective" "float fov" [ 10 ]
Film "rgb" "integer xresolution" [ 8 ] "integer yresolution" [ 8 ]
Sampler "independent" "integer pixelsamples" [ 4 ]
Integrator "path" "integer maxdepth" [ 1 ]
WorldBegin
)" + light + R"(
Material "diffuse" "rgb reflectance" [ 0.5 0.5 0.5 ]
Shape "trianglemesh" "point3 P" [ -10 0 -10  10 0 -10  10 0 10  -10 0 10 ] "integer indices" [ 0 1 2 0 2 3 ]
)";
  return testing::image_mean(film_mean(testing::render_text(scene).film));
}

class GoniometricLight : public ::testing::Test {
 protected:
  // 32x32 texels: `inside` where the equal-area square maps to the upper
  // hemisphere (|u - 1/2| + |v - 1/2| < 1/2), `outside` elsewhere.
  void write(float inside, float outside) {
    ImageRgb img{32, 32, std::vector<float>(32 * 32 * 3)};
    for (int y = 0; y < 32; ++y)
      for (int x = 0; x < 32; ++x) {
        const float u = (x + 0.5f) / 32, v = (y + 0.5f) / 32;
        const float value = std::abs(u - 0.5f) + std::abs(v - 0.5f) < 0.5f ? inside : outside;
        for (int c = 0; c < 3; ++c) img.rgb[3 * (y * 32 + x) + c] = value;
      }
    write_exr(path_, img, nullptr, {});
  }
  std::string light(const std::string& extra = "") const {
    return "AttributeBegin\nTranslate 0 2 0\n" + extra + "LightSource \"goniometric\" \"rgb I\" [ 4 4 4 ] \"string filename\" \"" +
           path_ + "\"\nAttributeEnd\n";
  }
  testing::TempFile file_{"gonio.exr"};
  const std::string& path_ = file_.path();
};

TEST_F(GoniometricLight, AUniformImageIsAPointLightOfItsValue) {
  write(0.5f, 0.5f);
  const double point = plane_radiance(R"(LightSource "point" "rgb I" [ 2 2 2 ] "point3 from" [ 0 2 0 ])");
  EXPECT_GT(point, 0.0);
  EXPECT_NEAR(plane_radiance(light()), point, 1e-6 * point);
}

TEST_F(GoniometricLight, TheImagesPoleIsTheLightsPlusY) {
  // The upper hemisphere of the image (its light-space +z) is world +y: the
  // plane below stays dark until the light is turned over.
  write(1.f, 0.f);
  EXPECT_EQ(plane_radiance(light()), 0.0);
  const double turned = plane_radiance(light("Rotate 180 1 0 0\n"));
  const double point = plane_radiance(R"(LightSource "point" "rgb I" [ 4 4 4 ] "point3 from" [ 0 2 0 ])");
  EXPECT_NEAR(turned, point, 1e-6 * point);
}

TEST_F(GoniometricLight, PowerIsPbrtV4s) {
  // pbrt-v4: I scaled by power / (4 pi mean(image)): a uniform 0.5 image
  // with power 8 pi emits intensity 4 whatever I is (I = (1, 1, 1)).
  write(0.5f, 0.5f);
  const double powered = plane_radiance("AttributeBegin\nTranslate 0 2 0\nLightSource \"goniometric\" \"string filename\" \"" +
                                        path_ + "\" \"float power\" " + std::to_string(8 * M_PI) + "\nAttributeEnd\n");
  const double point = plane_radiance(R"(LightSource "point" "rgb I" [ 2 2 2 ] "point3 from" [ 0 2 0 ])");
  EXPECT_NEAR(powered, point, 1e-5 * point);
}

TEST_F(GoniometricLight, AProjectionLightShinesItsSlideDownItsZAxis) {
  write(0.5f, 0.5f);  // any texel the window shows is 0.5
  auto projector = [&](const std::string& rotate, const std::string& fov) {
    return "AttributeBegin\nTranslate 0 2 0\n" + rotate + "LightSource \"projection\" \"float scale\" 4 \"float fov\" " +
           fov + " \"string filename\" \"" + path_ + "\"\nAttributeEnd\n";
  };
  const double point = plane_radiance(R"(LightSource "point" "rgb I" [ 2 2 2 ] "point3 from" [ 0 2 0 ])");
  // Rotate 90 about x turns the light's +z to -y: the plane sees the slide
  // (the view's 10 degrees lie inside a 90-degree window).
  EXPECT_NEAR(plane_radiance(projector("Rotate 90 1 0 0\n", "90")), point, 1e-5 * point);
  // Pointing up, or a window narrower than the view: dark, or partly dark.
  EXPECT_EQ(plane_radiance(projector("Rotate -90 1 0 0\n", "90")), 0.0);
  const double narrow = plane_radiance(projector("Rotate 90 1 0 0\n", "2"));
  EXPECT_GT(narrow, 0.0);
  EXPECT_LT(narrow, 0.5 * point);
}

}  // namespace
}  // namespace tessera
