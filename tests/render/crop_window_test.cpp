// pbrt-v4's "cropwindow" and "pixelbounds": only those pixels are rendered,
// and each holds what the whole image holds there (samples belong to the
// image's pixels, not to the film's).
#include <gtest/gtest.h>

#include <cstring>

#include "render_helpers.h"
#include "scene/pbrt_film.h"

namespace tessera {
namespace {

SceneDesc cornell(const std::string& film_extra) {
  SceneDesc d = load_pbrt_file(testing::source_dir() + "/scenes/cornell-box.pbrt");
  const std::string text = "Film \"rgb\" \"integer xresolution\" 40 \"integer yresolution\" 30 " + film_extra +
                           "\nWorldBegin\nShape \"sphere\"\n";
  const SceneDesc film_only = load_pbrt_string(text, "crop.pbrt", ".");
  d.film = film_only.film;
  d.spp = 8;
  return d;
}

TEST(CropWindow, ACropRendersThoseOfTheWholeImagesPixelsBitForBit) {
  const Film full = testing::render_desc(cornell(""), {}).film;
  // x from ceil(40 * 0.3) = 12 to ceil(40 * 0.75) = 30, y from 3 to 17.
  const Film crop = testing::render_desc(cornell("\"float cropwindow\" [ 0.3 0.75 0.1 0.55 ]"), {}).film;
  ASSERT_EQ(crop.width, 18);
  ASSERT_EQ(crop.height, 14);
  for (int y = 0; y < crop.height; ++y)
    for (int x = 0; x < crop.width; ++x) {
      const PixelAccum& a = crop.pixels[static_cast<size_t>(y) * crop.width + x];
      const PixelAccum& b = full.pixels[static_cast<size_t>(y + 3) * full.width + (x + 12)];
      ASSERT_EQ(std::memcmp(&a, &b, sizeof a), 0) << x << "," << y;
    }
  // pixelbounds name the same pixels directly.
  const Film bounds = testing::render_desc(cornell("\"integer pixelbounds\" [ 12 30 3 17 ]"), {}).film;
  EXPECT_TRUE(testing::films_identical(bounds, crop));
}

TEST(CropWindow, PbrtV4sRulesAndErrors) {
  auto film = [](const std::string& extra) {
    return load_pbrt_string("Film \"rgb\" \"integer xresolution\" 100 \"integer yresolution\" 50 " + extra +
                                "\nWorldBegin\nShape \"sphere\"\n",
                            "crop.pbrt", ".");
  };
  // Reversed and out-of-range corners are ordered and clamped, as pbrt-v4 does.
  PixelBounds pb = film_pixel_bounds(film("\"float cropwindow\" [ 0.8 0.25 -1 0.5 ]").film);
  EXPECT_EQ(pb.x0, 25);
  EXPECT_EQ(pb.x1, 80);
  EXPECT_EQ(pb.y0, 0);
  EXPECT_EQ(pb.y1, 25);
  // Pixel bounds beyond the image are clamped with a warning.
  const SceneDesc wide = film("\"integer pixelbounds\" [ 37 140 3 7 ]");
  pb = film_pixel_bounds(wide.film);
  EXPECT_EQ(pb.x0, 37);
  EXPECT_EQ(pb.x1, 100);
  EXPECT_EQ(pb.y1, 7);
  ASSERT_FALSE(wide.warnings.empty());
  EXPECT_NE(wide.warnings[0].find("pixelbounds"), std::string::npos);
  // The crop is a share of the picture: a changed resolution keeps it.
  FilmDesc half = film("\"integer pixelbounds\" [ 20 60 10 30 ]").film;
  half.xres = 50;
  half.yres = 25;
  pb = film_pixel_bounds(half);
  EXPECT_EQ(pb.x0, 10);
  EXPECT_EQ(pb.x1, 30);
  EXPECT_EQ(pb.y0, 5);
  EXPECT_EQ(pb.y1, 15);
  auto error = [&](const std::string& extra) {
    try {
      film(extra);
    } catch (const SceneError& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  EXPECT_NE(error("\"float cropwindow\" [ 0.5 0.5 0 1 ]").find("crop.pbrt:1: film \"pixelbounds\"/\"cropwindow\" leave no pixels"),
            std::string::npos);
  EXPECT_NE(error("\"float cropwindow\" [ 0 1 0 1 ] \"integer pixelbounds\" [ 0 10 0 10 ]").find("both"), std::string::npos);
  EXPECT_NE(error("\"integer pixelbounds\" [ 0 10 0 ]").find("four integers"), std::string::npos);
}

}  // namespace
}  // namespace tessera
