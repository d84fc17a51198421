// pbrt-v4's infinite-light portal: the sky emits only through the portal's
// front, and next-event estimation samples the portal's rectangle, so a room
// lit through a window gets the same image with less noise.
#include <gtest/gtest.h>

#include "render/error_estimate.h"
#include "render_helpers.h"

namespace tessera {
namespace {

// The window, ordered so that cross(p3 - p0, p1 - p0) points up, out of the room.
const char* kWindowPortal = "\"point3 portal\" [ -0.5 1 -0.5  0.5 1 -0.5  0.5 1 0.5  -0.5 1 0.5 ]";

// A closed 2 x 2 x 2 room of grey walls around the origin with a 1 x 1 window
// in its ceiling (y = 1), under a constant sky; the camera inside looks at
// the floor's corner. `portal`: the light's portal parameter, or "".
RenderResult room(const std::string& portal, uint64_t seed, const std::string& extra = "") {
  const std::string scene = R"(
LookAt 0 0.2 0.9  0 -1 -0.6  0 1 0
Camera "perspective" "float fov" [ 60 ]
Film "rgb" "integer xresolution" [ 16 ] "integer yresolution" [ 16 ]
Sampler "independent" "integer pixelsamples" [ 256 ] "integer seed" [ )" + std::to_string(seed) + R"( ]
Integrator "path" "integer maxdepth" [ 3 ]
WorldBegin
AttributeBegin
)" + extra + R"(
LightSource "infinite" "rgb L" [ 2 2 2 ] )" + portal + R"(
AttributeEnd
Material "diffuse" "rgb reflectance" [ 0.5 0.5 0.5 ]
# floor, walls (facing in)
Shape "trianglemesh" "point3 P" [ -1 -1 -1  1 -1 -1  1 -1 1  -1 -1 1 ] "integer indices" [ 0 2 1 0 3 2 ]
Shape "trianglemesh" "point3 P" [ -1 -1 -1  -1 1 -1  1 1 -1  1 -1 -1 ] "integer indices" [ 0 2 1 0 3 2 ]
Shape "trianglemesh" "point3 P" [ -1 -1 1  1 -1 1  1 1 1  -1 1 1 ] "integer indices" [ 0 2 1 0 3 2 ]
Shape "trianglemesh" "point3 P" [ -1 -1 -1  -1 -1 1  -1 1 1  -1 1 -1 ] "integer indices" [ 0 2 1 0 3 2 ]
Shape "trianglemesh" "point3 P" [ 1 -1 -1  1 1 -1  1 1 1  1 -1 1 ] "integer indices" [ 0 2 1 0 3 2 ]
# ceiling around the window x, z in [-0.5, 0.5]
Shape "trianglemesh" "point3 P" [ -1 1 -1  1 1 -1  1 1 -0.5  -1 1 -0.5 ] "integer indices" [ 0 1 2 0 2 3 ]
Shape "trianglemesh" "point3 P" [ -1 1 0.5  1 1 0.5  1 1 1  -1 1 1 ] "integer indices" [ 0 1 2 0 2 3 ]
Shape "trianglemesh" "point3 P" [ -1 1 -0.5  -0.5 1 -0.5  -0.5 1 0.5  -1 1 0.5 ] "integer indices" [ 0 1 2 0 2 3 ]
Shape "trianglemesh" "point3 P" [ 0.5 1 -0.5  1 1 -0.5  1 1 0.5  0.5 1 0.5 ] "integer indices" [ 0 1 2 0 2 3 ]
)";
  return testing::render_text(scene);
}


// The room's mean over two seeds.
double room_mean(const std::string& portal, const std::string& extra = "") {
  return 0.5 * (testing::image_mean(film_mean(room(portal, 1, extra).film)) +
                testing::image_mean(film_mean(room(portal, 2, extra).film)));
}

TEST(Portal, SameRoomThroughAnInterfaceAndUnderARotatedSky) {
  const double plain = room_mean("");
  // An "interface" sheet above the window: rays that cross it still see the
  // sky through the portal from where they last scattered (weights sum to 1).
  const std::string sheet =
      "AttributeBegin\nMaterial \"interface\"\nShape \"trianglemesh\" \"point3 P\" [ -3 1.2 -3  3 1.2 -3  3 1.2 3  -3 1.2 3 ] "
      "\"integer indices\" [ 0 1 2 0 2 3 ]\nAttributeEnd\n";
  EXPECT_NEAR(room_mean(kWindowPortal, sheet) / plain, 1.0, 0.03);
  // The portal's points are world points: a transform before the light turns its sky, not its window.
  EXPECT_NEAR(room_mean(kWindowPortal, "Rotate -90 1 0 0\n") / plain, 1.0, 0.03);
}

TEST(Portal, SameRoomLessNoise) {
  double plain_mean = 0, portal_mean = 0, plain_err = 0, portal_err = 0;
  for (uint64_t seed : {1, 2}) {
    const RenderResult a = room("", seed), b = room(kWindowPortal, seed);
    plain_mean += testing::image_mean(film_mean(a.film)) / 2;
    portal_mean += testing::image_mean(film_mean(b.film)) / 2;
    plain_err += estimate_rel_mse(a.film).rel_mse / 2;
    portal_err += estimate_rel_mse(b.film).rel_mse / 2;
  }
  ASSERT_GT(plain_mean, 0.02);
  EXPECT_NEAR(portal_mean / plain_mean, 1.0, 0.03);
  EXPECT_LT(portal_err, 0.5 * plain_err);
}

// The sky seen from below the window at the origin (y = 1, 1 x 1), with a
// 120-degree view: only through the rectangle.
ImageRgb sky(const std::string& look) {
  const std::string scene = look + R"(
Camera "perspective" "float fov" [ 120 ]
Film "rgb" "integer xresolution" [ 8 ] "integer yresolution" [ 8 ]
Sampler "independent" "integer pixelsamples" [ 4 ]
WorldBegin
LightSource "infinite" "rgb L" [ 1 1 1 ] )" + std::string(kWindowPortal) + "\n";
  return film_mean(testing::render_text(scene).film);
}

TEST(Portal, TheSkyEmitsOnlyThroughTheRectangle) {
  const ImageRgb up = sky("LookAt 0 0 0  0 1 0  0 0 1");
  EXPECT_NEAR(up.rgb[3 * (4 * 8 + 4)], 1.f, 1e-6f);  // the centre looks through the window
  EXPECT_NEAR(up.rgb[0], 0.f, 1e-6f);                // a corner, 60 degrees off, does not
  EXPECT_GT(testing::image_mean(up), 0.05);
  EXPECT_LT(testing::image_mean(up), 0.5);
  EXPECT_NEAR(testing::image_mean(sky("LookAt 0 0 0  0 -1 0  0 0 1")), 0.0, 1e-6);  // behind its plane
}

TEST(Portal, MustBeARectangle) {
  auto error = [](const std::string& portal) {
    try {
      load_pbrt_string("WorldBegin\nLightSource \"infinite\" \"point3 portal\" [ " + portal + " ]\n", "p.pbrt", ".");
    } catch (const SceneError& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  EXPECT_NE(error("0 0 0  1 0 0  1 1 0.5  0 1 0").find("p.pbrt:2: infinite light \"portal\" is not a rectangle"),
            std::string::npos);
  EXPECT_NE(error("0 0 0  1 0 0  1 1 0").find("needs 4 points"), std::string::npos);
  EXPECT_EQ(error("0 0 0  2 0 0  2 1 0  0 1 0"), "");
}

}  // namespace
}  // namespace tessera
