// Quads without uv (bilinear patches, PLY quads) read pbrt-v4's per-patch uv
// (0,0) (1,0) (0,1) (1,1) on both of their triangles.
#include <gtest/gtest.h>

#include "kernels/surface.h"
#include "render_helpers.h"

namespace tessera {
namespace {

TEST(QuadUv, BothHalvesOfAPatchReadItsUv) {
  // Two patches sharing an edge, p00 p10 p01 p11 each.
  SceneData scene(load_pbrt_string(
      "WorldBegin\nShape \"bilinearmesh\" \"point3 P\" [ 0 0 0  1 0 0  0 1 0  1 1 0  2 0 0  2 1 0 ]"
      " \"integer indices\" [ 0 1 2 3  1 4 3 5 ]\n",
      "quads.pbrt", "."));
  const SceneView& v = scene.view();
  ASSERT_EQ(scene.num_triangles(), 4u);
  for (uint32_t patch = 0; patch < 2; ++patch) {
    const uint32_t first = 2 * patch, second = first + 1;
    // First half (p00, p10, p11).
    EXPECT_EQ(triangle_uv(v, first, 1.f, 0.f), Vec2(1.f, 0.f));
    EXPECT_EQ(triangle_uv(v, first, 0.f, 1.f), Vec2(1.f, 1.f));
    // Second half (p00, p11, p01).
    EXPECT_EQ(triangle_uv(v, second, 0.f, 0.f), Vec2(0.f, 0.f));
    EXPECT_EQ(triangle_uv(v, second, 1.f, 0.f), Vec2(1.f, 1.f));
    EXPECT_EQ(triangle_uv(v, second, 0.f, 1.f), Vec2(0.f, 1.f));
    // dp/du runs along p00 -> p10 on both halves.
    EXPECT_EQ(surface_dpdu(v, second), surface_dpdu(v, first));
  }
  // A triangle mesh keeps pbrt-v4's triangle default.
  SceneData tri(load_pbrt_string("WorldBegin\nShape \"trianglemesh\" \"point3 P\" [ 0 0 0 1 0 0 1 1 0 0 1 0 ]"
                                 " \"integer indices\" [ 0 1 2 0 2 3 ]\n",
                                 "tris.pbrt", "."));
  EXPECT_EQ(triangle_uv(tri.view(), 1, 0.f, 1.f), Vec2(1.f, 1.f));
}

}  // namespace
}  // namespace tessera
