// Roughness given by a texture is evaluated at each hit, then remapped as
// pbrt-v4 does (alpha = sqrt(roughness) unless remaproughness is false).
#include <gtest/gtest.h>

#include "render_helpers.h"

namespace tessera {
namespace {

std::string glossy_plane(const std::string& textures, const std::string& roughness) {
  return R"(
LookAt 0 3 -3  0 0 0  0 1 0
Camera "perspective" "float fov" [ 40 ]
Film "rgb" "integer xresolution" [ 24 ] "integer yresolution" [ 24 ]
Sampler "independent" "integer pixelsamples" [ 16 ]
Integrator "path" "integer maxdepth" [ 2 ]
WorldBegin
LightSource "point" "rgb I" [ 10 10 10 ] "point3 from" [ 0 3 3 ]
)" + textures + R"(
Material "conductor" )" + roughness + R"(
Shape "trianglemesh" "point3 P" [ -5 0 -5  5 0 -5  5 0 5  -5 0 5 ] "integer indices" [ 0 1 2 0 2 3 ]
  "point2 uv" [ 0 0 1 0 1 1 0 1 ]
)";
}

TEST(TexturedRoughness, EvaluatedPerHitAndRemappedAsPbrt) {
  // A checkerboard whose two checks are both 0.09 is a texture evaluated at
  // every hit, with the value of the constant: the same image.
  const std::string same = "Texture \"r\" \"float\" \"checkerboard\" \"float tex1\" 0.09 \"float tex2\" 0.09\n";
  const Film constant = testing::render_text(glossy_plane("", "\"float roughness\" 0.09")).film;
  const Film textured = testing::render_text(glossy_plane(same, "\"texture roughness\" \"r\"")).film;
  EXPECT_TRUE(testing::films_identical(constant, textured));
  // Without remapping, 0.3 is the alpha that roughness 0.09 remaps to.
  const Film unmapped = testing::render_text(glossy_plane(
      "Texture \"r\" \"float\" \"checkerboard\" \"float tex1\" 0.3 \"float tex2\" 0.3\n",
      "\"texture roughness\" \"r\" \"bool remaproughness\" false")).film;
  const ImageRgb a = film_mean(constant), b = film_mean(unmapped);
  for (size_t i = 0; i < a.rgb.size(); ++i) EXPECT_NEAR(a.rgb[i], b.rgb[i], 1e-5f * (1.f + a.rgb[i]));
  // Checks of different roughness give a different image.
  const Film mixed = testing::render_text(glossy_plane(
      "Texture \"r\" \"float\" \"checkerboard\" \"float uscale\" 4 \"float vscale\" 4 \"float tex1\" 0.01 \"float tex2\" 0.5\n",
      "\"texture roughness\" \"r\"")).film;
  EXPECT_FALSE(testing::films_identical(constant, mixed));
}

}  // namespace
}  // namespace tessera
