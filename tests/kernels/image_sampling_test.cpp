// Image lookups as pbrt-v4's Image does them: bilinear and nearest ("point")
// reads, and the four wrap modes outside [0, 1] (pbrt-v4's RemapPixelCoords).
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "kernels/image_sampling.h"

namespace tessera {
namespace {

// 4x2 texels; texel (x, y) holds 10 y + x + 1 in every channel.
struct TestImage {
  std::vector<Rgb> texels;
  ImageView view;
  TestImage() {
    for (int y = 0; y < 2; ++y)
      for (int x = 0; x < 4; ++x) texels.push_back(Rgb(10.f * y + x + 1.f));
    view = ImageView{4, 2, texels.data()};
  }
};

Float at(const ImageView& img, Float s, Float t, ImageWrap wrap, ImageFilter filter = ImageFilter::Bilinear) {
  return image_lookup(img, Vec2(s, t), wrap, filter).x;
}

TEST(ImageSampling, TexelCentresReadTheirTexelInEveryMode) {
  TestImage img;
  for (ImageWrap w : {ImageWrap::Repeat, ImageWrap::Black, ImageWrap::Clamp, ImageWrap::OctahedralSphere}) {
    // t is flipped: t = 0.75 is the top row (y = 0).
    EXPECT_FLOAT_EQ(at(img.view, 0.125f, 0.75f, w), 1.f);
    EXPECT_FLOAT_EQ(at(img.view, 0.625f, 0.25f, w), 13.f);
    EXPECT_FLOAT_EQ(at(img.view, 0.375f, 0.5f, w), 0.5f * (2.f + 12.f));  // between the rows
  }
}

TEST(ImageSampling, RepeatWrapsBlackFadesClampHoldsTheEdge) {
  TestImage img;
  // s = 0 is halfway between texel -1 and texel 0 of the top row.
  EXPECT_FLOAT_EQ(at(img.view, 0.f, 0.75f, ImageWrap::Repeat), 0.5f * (4.f + 1.f));
  EXPECT_FLOAT_EQ(at(img.view, 0.f, 0.75f, ImageWrap::Black), 0.5f * 1.f);
  EXPECT_FLOAT_EQ(at(img.view, 0.f, 0.75f, ImageWrap::Clamp), 1.f);
  // Far outside: a whole period away, nothing, the corner texel.
  EXPECT_FLOAT_EQ(at(img.view, 3.125f, 0.75f, ImageWrap::Repeat), 1.f);
  EXPECT_FLOAT_EQ(at(img.view, -7.f, 0.75f, ImageWrap::Black), 0.f);
  EXPECT_FLOAT_EQ(at(img.view, 1e30f, -1e30f, ImageWrap::Clamp), 14.f);  // right column, bottom row
  EXPECT_FLOAT_EQ(at(img.view, -1e30f, 1e30f, ImageWrap::Clamp), 1.f);
}

TEST(ImageSampling, OctahedralSphereMirrorsAcrossTheEdges) {
  TestImage img;
  // pbrt-v4: x = -1 becomes x = 1 with y mirrored; y = -1 becomes y = 1 with x mirrored.
  EXPECT_FLOAT_EQ(image_texel(img.view, -1, 0, ImageWrap::OctahedralSphere).x, 12.f);
  EXPECT_FLOAT_EQ(image_texel(img.view, 4, 1, ImageWrap::OctahedralSphere).x, 4.f);
  EXPECT_FLOAT_EQ(image_texel(img.view, 1, -1, ImageWrap::OctahedralSphere).x, 13.f);
  EXPECT_FLOAT_EQ(image_texel(img.view, 2, 2, ImageWrap::OctahedralSphere).x, 12.f);
  // Anything further stays inside the image.
  const Float far = at(img.view, 1e30f, NAN, ImageWrap::OctahedralSphere);
  EXPECT_TRUE(far >= 1.f && far <= 14.f) << far;
}

TEST(ImageSampling, PointFilterReadsTheNearestTexel) {
  TestImage img;
  EXPECT_FLOAT_EQ(at(img.view, 0.3f, 0.8f, ImageWrap::Repeat, ImageFilter::Point), 2.f);
  EXPECT_FLOAT_EQ(at(img.view, 0.3f, 0.2f, ImageWrap::Repeat, ImageFilter::Point), 12.f);
  EXPECT_FLOAT_EQ(at(img.view, 1.05f, 0.8f, ImageWrap::Black, ImageFilter::Point), 0.f);
  EXPECT_FLOAT_EQ(at(img.view, 1.05f, 0.8f, ImageWrap::Clamp, ImageFilter::Point), 4.f);
  EXPECT_FLOAT_EQ(at(img.view, 1.05f, 0.8f, ImageWrap::Repeat, ImageFilter::Point), 1.f);
}

TEST(ImageSampling, NonFiniteCoordinatesReadATexel) {
  TestImage img;
  for (ImageWrap w : {ImageWrap::Repeat, ImageWrap::Black, ImageWrap::Clamp, ImageWrap::OctahedralSphere})
    for (ImageFilter f : {ImageFilter::Bilinear, ImageFilter::Point}) {
      const Float v = at(img.view, NAN, INFINITY, w, f);
      EXPECT_TRUE(std::isfinite(v) && v >= 0.f && v <= 14.f) << v;
    }
}

}  // namespace
}  // namespace tessera
