// Every shipped scene loads and renders without NaN/Inf samples.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>

#include "render_helpers.h"

namespace tessera {
namespace {

TEST(ShippedScenes, RenderWithoutNonFiniteValues) {
  namespace fs = std::filesystem;
  int rendered = 0;
  for (const auto& entry : fs::directory_iterator(testing::source_dir() + "/scenes")) {
    if (entry.path().extension() != ".pbrt") continue;
    SCOPED_TRACE(entry.path().string());
    SceneDesc d = load_pbrt_file(entry.path().string());
    d.film.xres = 32;
    d.film.yres = 32;
    d.spp = 8;
    RenderResult r = testing::render_desc(std::move(d), {});
    EXPECT_EQ(r.stats.counters.rejected_nonfinite, 0u);
    EXPECT_EQ(r.stats.counters.rejected_negative, 0u);
    ImageRgb img = film_mean(r.film);
    double sum = 0;
    for (float v : img.rgb) {
      ASSERT_TRUE(std::isfinite(v));
      sum += v;
    }
    EXPECT_GT(sum, 0.0) << "scene renders black";
    ++rendered;
  }
  EXPECT_GE(rendered, 5);
}

}  // namespace
}  // namespace tessera
