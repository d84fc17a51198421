// Lights and media under a moving transform keep their start transform,
// with a warning, as pbrt-v4 does ("Animated lights aren't supported. Using
// the start transform.", and the same for media).
#include <gtest/gtest.h>

#include "scene_test_helpers.h"

namespace tessera {
namespace {

using test::kTriangle;
using test::load_world;

TEST(MovingLightsAndMedia, StayAtTheirStartTransformWithAWarning) {
  SceneDesc s = load_world(
      "AttributeBegin\nActiveTransform EndTime\nTranslate 5 0 0\nActiveTransform All\n"
      "LightSource \"point\" \"point3 from\" [ 1 2 3 ] \"rgb I\" [ 1 1 1 ]\n"
      "MakeNamedMedium \"fog\" \"string type\" \"homogeneous\"\n"
      "AttributeEnd\n" + std::string(kTriangle));
  ASSERT_EQ(s.lights.size(), 1u);
  EXPECT_NEAR(s.lights[0].position.x + static_cast<Float>(s.render_origin.x), 1.f, 1e-5f);  // not 6
  ASSERT_EQ(s.warnings.size(), 2u);
  EXPECT_NE(s.warnings[0].find("test.pbrt:6: a moving light stays where it starts (pbrt-v4"), std::string::npos)
      << s.warnings[0];
  EXPECT_NE(s.warnings[1].find("test.pbrt:7: a moving medium stays where it starts (pbrt-v4"), std::string::npos)
      << s.warnings[1];
}

}  // namespace
}  // namespace tessera
