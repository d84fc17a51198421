// pbrt-v4's orthographic and spherical cameras and the screen window:
// directions and origins of camera rays, and pictures whose coverage is
// known exactly.
#include <gtest/gtest.h>

#include <cmath>

#include "kernels/camera.h"
#include "render_helpers.h"

namespace tessera {
namespace {

CameraView camera(CameraProjection p, int w, int h) {
  CameraView c;
  c.projection = p;
  c.width = w;
  c.height = h;
  c.screen_min = Vec2(-1.f, -1.f);
  c.screen_max = Vec2(1.f, 1.f);
  return c;
}

#define EXPECT_DIR_NEAR(a, b)                 \
  do {                                        \
    const Vec3 a_ = (a), b_ = (b);            \
    EXPECT_NEAR(a_.x, b_.x, 1e-5f) << "x";    \
    EXPECT_NEAR(a_.y, b_.y, 1e-5f) << "y";    \
    EXPECT_NEAR(a_.z, b_.z, 1e-5f) << "z";    \
  } while (0)

TEST(CameraProjection, OrthographicRaysAreParallelFromTheScreenWindow) {
  CameraView c = camera(CameraProjection::Orthographic, 20, 10);
  c.screen_min = Vec2(-2.f, -1.f);
  c.screen_max = Vec2(2.f, 1.f);
  c.origin = Vec3(1.f, 2.f, 3.f);
  const Ray corner = generate_camera_ray(c, Vec2(0.f, 0.f));  // raster (0, 0): screen (x0, y1)
  EXPECT_DIR_NEAR(corner.o, Vec3(-1.f, 3.f, 3.f));
  EXPECT_DIR_NEAR(corner.d, Vec3(0.f, 0.f, 1.f));
  const Ray centre = generate_camera_ray(c, Vec2(10.f, 5.f));
  EXPECT_DIR_NEAR(centre.o, c.origin);
  // A lens focused at 4: every lens point's ray meets the pinhole ray there,
  // leaving (as pbrt-v4 writes it) from the lens around the camera's origin.
  const Ray pinhole = generate_camera_ray(c, Vec2(15.f, 2.f));
  c.lens_radius = 0.3f;
  c.focal_distance = 4.f;
  for (Vec2 u : {Vec2(0.1f, 0.7f), Vec2(0.9f, 0.2f)}) {
    const Ray r = generate_camera_ray(c, Vec2(15.f, 2.f), u);
    EXPECT_LE(glm::length(r.o - c.origin), 0.3f + 1e-6f);
    const Vec3 focus = r.o + r.d * ((c.origin.z + 4.f - r.o.z) / r.d.z);
    EXPECT_DIR_NEAR(focus, pinhole.o + Vec3(0.f, 0.f, 4.f));
  }
}

TEST(CameraProjection, SphericalDirectionsFollowPbrtV4) {
  // Equirectangular: v = theta / pi, u = phi / 2 pi about camera-space y (up) after pbrt-v4's y/z swap.
  const CameraView e = camera(CameraProjection::SphericalEquirectangular, 40, 20);
  EXPECT_DIR_NEAR(generate_camera_ray(e, Vec2(20.f, 10.f)).d, Vec3(-1.f, 0.f, 0.f));  // theta pi/2, phi pi
  EXPECT_DIR_NEAR(generate_camera_ray(e, Vec2(10.f, 5.f)).d, Vec3(0.f, std::sqrt(0.5f), std::sqrt(0.5f)));
  EXPECT_DIR_NEAR(generate_camera_ray(e, Vec2(0.f, 0.f)).d, Vec3(0.f, 1.f, 0.f));  // top row: up
  // Equal-area: the square's centre is the pole (up), its corners the other pole.
  const CameraView a = camera(CameraProjection::SphericalEqualArea, 16, 16);
  EXPECT_DIR_NEAR(generate_camera_ray(a, Vec2(8.f, 8.f)).d, Vec3(0.f, 1.f, 0.f));
  EXPECT_DIR_NEAR(generate_camera_ray(a, Vec2(0.f, 0.f)).d, Vec3(0.f, -1.f, 0.f));
  for (Vec2 p : {Vec2(3.f, 11.f), Vec2(13.5f, 2.25f)})
    EXPECT_NEAR(glm::length(generate_camera_ray(a, p).d), 1.f, 1e-5f);
}

// A two-sided emitter (L = 1) at z = 20 behind a black unit square at
// depth `z`, seen along +z from the origin; the image's mean.
double square_seen(const std::string& camera_line, double z) {
  const std::string zs = std::to_string(z);
  const std::string scene = "LookAt 0 0 0  0 0 1  0 1 0\n" + camera_line + R"(
Film "rgb" "integer xresolution" [ 32 ] "integer yresolution" [ 32 ]
Sampler "independent" "integer pixelsamples" [ 64 ]
PixelFilter "box"
Integrator "path" "integer maxdepth" [ 1 ]
WorldBegin
AttributeBegin
AreaLightSource "diffuse" "rgb L" [ 1 1 1 ] "bool twosided" true
Shape "trianglemesh" "point3 P" [ -100 -100 20  100 -100 20  100 100 20  -100 100 20 ] "integer indices" [ 0 1 2 0 2 3 ]
AttributeEnd
Material "diffuse" "rgb reflectance" [ 0 0 0 ]
Shape "trianglemesh" "point3 P" [ -0.5 -0.5 )" + zs + "  0.5 -0.5 " + zs + "  0.5 0.5 " + zs + "  -0.5 0.5 " + zs +
                            R"( ] "integer indices" [ 0 1 2 0 2 3 ]
)";
  return testing::image_mean(film_mean(testing::render_text(scene).film));
}

TEST(CameraProjection, OrthographicCoverageDoesNotDependOnDistance) {
  // The default screen window [-1, 1]^2: the unit square hides a quarter at any depth.
  EXPECT_NEAR(square_seen("Camera \"orthographic\"", 3.0), 0.75, 1e-6);
  EXPECT_NEAR(square_seen("Camera \"orthographic\"", 10.0), 0.75, 1e-6);
  // A screen window of the square's size: it hides everything.
  EXPECT_NEAR(square_seen("Camera \"orthographic\" \"float screenwindow\" [ -0.5 0.5 -0.5 0.5 ]", 10.0), 0.0, 1e-6);
  // Perspective, for contrast: nearer is larger.
  EXPECT_LT(square_seen("Camera \"perspective\" \"float fov\" [ 30 ]", 3.0),
            square_seen("Camera \"perspective\" \"float fov\" [ 30 ]", 10.0));
}

TEST(CameraProjection, SphericalCameraSeesTheUpperHemisphereWhereExpected) {
  // An emitter box around the camera, lit only on its top face (y = 5):
  // equirectangular images show it in their top rows, equal-area ones at the centre.
  auto render = [](const std::string& mapping) {
    const std::string scene = R"(
LookAt 0 0 0  0 0 1  0 1 0
Camera "spherical" "string mapping" ")" + mapping + R"("
Film "rgb" "integer xresolution" [ 32 ] "integer yresolution" [ 32 ]
Sampler "independent" "integer pixelsamples" [ 16 ]
Integrator "path" "integer maxdepth" [ 1 ]
WorldBegin
AreaLightSource "diffuse" "rgb L" [ 1 1 1 ] "bool twosided" true
Shape "trianglemesh" "point3 P" [ -1000 5 -1000  1000 5 -1000  1000 5 1000  -1000 5 1000 ] "integer indices" [ 0 1 2 0 2 3 ]
)";
    return film_mean(testing::render_text(scene).film);
  };
  auto pixel = [](const ImageRgb& img, int x, int y) { return img.rgb[3 * (y * 32 + x)]; };
  const ImageRgb equirect = render("equirectangular");
  EXPECT_NEAR(pixel(equirect, 5, 2), 1.f, 1e-6f);
  EXPECT_NEAR(pixel(equirect, 20, 29), 0.f, 1e-6f);
  const ImageRgb equal_area = render("equalarea");
  EXPECT_NEAR(pixel(equal_area, 16, 16), 1.f, 1e-6f);
  EXPECT_NEAR(pixel(equal_area, 1, 1), 0.f, 1e-6f);
  EXPECT_NEAR(pixel(equal_area, 30, 30), 0.f, 1e-6f);
  // Half the sphere (up to the plane's finite size): half the equal-area image, a bit under.
  const double mean = testing::image_mean(equal_area);
  EXPECT_GT(mean, 0.48);
  EXPECT_LT(mean, 0.501);
}

TEST(CameraProjection, BadParametersAreErrors) {
  auto error = [](const std::string& camera) {
    try {
      load_pbrt_string(camera + "\nWorldBegin\nLightSource \"infinite\"\n", "cam.pbrt", ".");
    } catch (const SceneError& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  EXPECT_NE(error("Camera \"spherical\" \"string mapping\" \"cubemap\"").find("cam.pbrt:1: spherical camera \"mapping\""),
            std::string::npos);
  EXPECT_NE(error("Camera \"orthographic\" \"float screenwindow\" [ 1 1 -1 1 ]").find("\"screenwindow\" needs"),
            std::string::npos);
  EXPECT_EQ(error("Camera \"orthographic\" \"float screenwindow\" [ 1 -1 -1 1 ]"), "");  // mirrored, as pbrt-v4
  EXPECT_NE(error("Camera \"perspective\" \"float frameaspectratio\" -2").find("\"frameaspectratio\" must be positive"),
            std::string::npos);
}

}  // namespace
}  // namespace tessera
