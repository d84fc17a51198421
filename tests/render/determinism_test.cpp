// Same seed -> bit-identical image, whatever the thread count or tile size;
// a different seed -> a different image.
#include <gtest/gtest.h>

#include <cstring>

#include "render_helpers.h"
#include "scene/builtin_scenes.h"

namespace tessera {
namespace {

RenderResult render_cornell(int threads, int tile, uint64_t seed) {
  SceneDesc d = load_builtin_cornell_box();
  d.film.xres = 48;
  d.film.yres = 40;
  d.spp = 6;
  RenderOptions opt;
  opt.threads = threads;
  opt.tile_size = tile;
  opt.seed = seed;
  return testing::render_desc(std::move(d), opt);
}

TEST(Determinism, BitIdenticalAcrossThreadCountsAndTiles) {
  RenderResult one = render_cornell(1, 16, 42);
  RenderResult two = render_cornell(2, 16, 42);
  RenderResult four = render_cornell(4, 7, 42);
  EXPECT_TRUE(testing::films_identical(one.film, two.film));
  EXPECT_TRUE(testing::films_identical(one.film, four.film));
  EXPECT_EQ(one.stats.counters.path.rays, four.stats.counters.path.rays);
}

TEST(Determinism, SeedChangesTheImage) {
  RenderResult a = render_cornell(2, 16, 1);
  RenderResult b = render_cornell(2, 16, 2);
  EXPECT_FALSE(testing::films_identical(a.film, b.film));
}

}  // namespace
}  // namespace tessera
