// Bump mapping (a material's "displacement" texture, pbrt-v4's BumpMap): a
// displacement rising linearly along u tilts the shading normal by the slope.
#include <gtest/gtest.h>

#include <cstring>
#include <filesystem>
#include <fstream>

#include "kernels/bump.h"
#include "render_helpers.h"

namespace tessera {
namespace {

// A 256 x 1 linear ramp 0..1 as a PFM (bilinear lookups make it linear in u).
std::string write_ramp(const std::filesystem::path& dir) {
  std::string bytes = "Pf\n256 1\n-1.0\n";
  for (int x = 0; x < 256; ++x) {
    const float v = x / 255.f;
    char b[4];
    std::memcpy(b, &v, 4);
    bytes.append(b, 4);
  }
  std::filesystem::create_directories(dir);
  const std::string path = (dir / "ramp.pfm").string();
  std::ofstream(path, std::ios::binary) << bytes;
  return path;
}

// A 2 x 2 quad in z = 0, u along x (dp/du = (2, 0, 0), dp/dv = (0, 2, 0)),
// after `world`'s textures and material.
std::string quad_scene(const std::string& world) {
  return "WorldBegin\n" + world +
         "Shape \"trianglemesh\" \"point3 P\" [ 0 0 0  2 0 0  2 2 0  0 2 0 ] "
         "\"integer indices\" [ 0 1 2 0 2 3 ] \"point2 uv\" [ 0 0 1 0 1 1 0 1 ]\n";
}

TEST(Bump, LinearDisplacementTiltsTheNormalByItsSlope) {
  const auto dir = std::filesystem::temp_directory_path() / "tessera_bump_test";
  const std::string ramp = write_ramp(dir);
  const std::string scene = quad_scene("Texture \"ramp\" \"float\" \"imagemap\" \"string filename\" \"" + ramp +
                                        "\" \"string encoding\" \"linear\" \"float scale\" 0.5\n"
                                        "Material \"diffuse\" \"texture displacement\" \"ramp\"\n");
  SceneData data(load_pbrt_string(scene, "<bump>", "."));
  const SceneView& s = data.view();
  ASSERT_GE(s.materials[s.triangles[0].material].bump, 0);
  // d(u) = 0.5 * (256 u - 0.5) / 255 between texel centres: slope k = 0.5 * 256 / 255 per unit u.
  const Float k = 0.5f * 256.f / 255.f, L = 2.f;
  for (Float b2 : {0.2f, 0.35f}) {
    const SurfaceHit h = make_surface_hit(s, 0, 0.3f, b2);
    const Vec3 n = bumped_shading_normal(s, s.materials[s.triangles[0].material].bump, h);
    EXPECT_NEAR(glm::length(n), 1.f, 1e-5f);
    EXPECT_GT(glm::dot(n, h.ng), 0.f);
    EXPECT_NEAR(n.y, 0.f, 1e-4f);
    // cross(dpdu + k n, dpdv) is (-k L, 0, L^2) up to sign and scale.
    EXPECT_NEAR(std::abs(n.x / n.z), k / L, 2e-3f);
  }
  std::filesystem::remove_all(dir);
}

// A displacement read through the hit point, not its uv (a planar mapping,
// like pbrt-v4's 3D textures): pbrt-v4 moves the point along dp/du and
// dp/dv as it steps u and v, so the slope in space becomes a slope in u.
TEST(Bump, PointMappedDisplacementTiltsTheNormalToo) {
  // d = 0.5 x; the quad is 2 x 2 with u along x, so d rises by 1 per unit u.
  const std::string scene = quad_scene(
      "Texture \"x\" \"float\" \"bilerp\" \"string mapping\" \"planar\" \"float v10\" 1 \"float v11\" 1 "
      "\"float v01\" 0\n"
      "Texture \"d\" \"float\" \"scale\" \"texture tex\" \"x\" \"float scale\" 0.5\n"
      "Material \"diffuse\" \"texture displacement\" \"d\"\n");
  SceneData data(load_pbrt_string(scene, "<bump>", "."));
  const SceneView& s = data.view();
  const SurfaceHit h = make_surface_hit(s, 0, 0.3f, 0.2f);
  const Vec3 n = bumped_shading_normal(s, s.materials[s.triangles[0].material].bump, h);
  // cross(dpdu + 1 n, dpdv) = cross((2, 0, 1), (0, 2, 0)) = (-2, 0, 4).
  EXPECT_NEAR(n.y, 0.f, 1e-4f);
  EXPECT_NEAR(n.x / n.z, -0.5f, 2e-3f);
}

TEST(Bump, NormalMapRgbIsATangentSpaceNormal) {
  const auto dir = std::filesystem::temp_directory_path() / "tessera_normal_map_test";
  std::filesystem::create_directories(dir);
  // One texel: 2 rgb - 1 = (0.5, 0, 0.866), 30 degrees from the normal towards dp/du.
  const float rgb[3] = {0.75f, 0.5f, 0.5f + 0.4330127f};
  std::string bytes = "PF\n1 1\n-1.0\n";
  bytes.append(reinterpret_cast<const char*>(rgb), sizeof rgb);
  const std::string path = (dir / "n.pfm").string();
  std::ofstream(path, std::ios::binary) << bytes;
  const std::string scene = quad_scene("Material \"diffuse\" \"string normalmap\" \"" + path + "\"\n");
  SceneData data(load_pbrt_string(scene, "<normalmap>", "."));
  const SceneView& s = data.view();
  const int32_t image = s.materials[s.triangles[0].material].normal_map;
  ASSERT_GE(image, 0);
  const SurfaceHit h = make_surface_hit(s, 0, 0.3f, 0.2f);
  const Vec3 n = normal_mapped_shading_normal(s, image, h);
  const Vec3 expected = glm::normalize(0.5f * glm::normalize(surface_dpdu(s, 0)) + 0.8660254f * h.ns);
  EXPECT_NEAR(glm::dot(n, expected), 1.f, 1e-5f);
  EXPECT_NEAR(glm::dot(n, h.ns), 0.8660254f, 1e-4f);
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace tessera
