// compare_images on tiny hand-made images whose relMSE, MAPE and RMSE are
// worked out by hand: the regulariser kRelMseEpsilon, MAPE on luminance
// with the reference in the denominator, NaN/Inf pixels counted and left
// out, and a size mismatch refused. compare_blocks: the worst block ratio,
// where it is, the share of blocks off by more than 10 %, partial edge
// blocks, and too-dark reference blocks left unjudged.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include "render/image_metrics.h"

namespace tessera {
namespace {

// A w x h image, every pixel the given RGB.
ImageRgb uniform(int32_t w, int32_t h, float r, float g, float b) {
  ImageRgb img{w, h, std::vector<float>(static_cast<size_t>(w) * h * 3)};
  for (size_t i = 0; i < img.rgb.size(); i += 3) {
    img.rgb[i] = r;
    img.rgb[i + 1] = g;
    img.rgb[i + 2] = b;
  }
  return img;
}

void set_pixel(ImageRgb& img, int32_t i, float r, float g, float b) {
  img.rgb[3 * i] = r;
  img.rgb[3 * i + 1] = g;
  img.rgb[3 * i + 2] = b;
}

double luminance(double r, double g, double b) { return 0.2126 * r + 0.7152 * g + 0.0722 * b; }

// The metrics are accumulated in double from float pixels: the expected
// values below are computed from the same float inputs, so they agree to
// a few ulps of a double.
constexpr double kTol = 1e-12;

TEST(ImageMetrics, IdenticalImagesHaveZeroError) {
  ImageRgb a = uniform(3, 2, 0.25f, 4.f, 0.f);
  ImageErrors e = compare_images(a, a);
  EXPECT_EQ(e.rel_mse, 0.0);
  EXPECT_EQ(e.mape, 0.0);
  EXPECT_EQ(e.rmse, 0.0);
  EXPECT_EQ(e.pixels, 6u);
  EXPECT_EQ(e.nonfinite_pixels, 0u);
  EXPECT_EQ(e.reference_nonfinite_pixels, 0u);
}

TEST(ImageMetrics, UniformTenPercentTooBright) {
  // Reference 1 everywhere, image 1.1: d = 0.1, relMSE = d^2 / (1 + 0.01),
  // MAPE = |1 - 1.1| / 1 (luminance weights sum to 1), RMSE = d.
  ImageRgb ref = uniform(4, 3, 1.f, 1.f, 1.f), img = uniform(4, 3, 1.1f, 1.1f, 1.1f);
  ImageErrors e = compare_images(img, ref);
  const double d = double(1.1f) - 1.0;  // 0.1 as float arithmetic sees it
  EXPECT_NEAR(e.rel_mse, d * d / 1.01, kTol);
  EXPECT_NEAR(e.rel_mse, 0.01 / 1.01, 1e-8);  // the textbook value, within float's 0.1
  EXPECT_NEAR(e.mape, d, kTol);
  EXPECT_NEAR(e.rmse, d, kTol);
  EXPECT_EQ(e.pixels, 12u);
  for (int c = 0; c < 3; ++c) {
    EXPECT_NEAR(e.mean_image[c], double(1.1f), kTol);
    EXPECT_NEAR(e.mean_reference[c], 1.0, kTol);
  }
}

TEST(ImageMetrics, PerChannelDenominatorsAndLuminanceMape) {
  // One pixel, reference (1, 2, 0.5), image (1.5, 2, 0.5): only red is off.
  // relMSE divides by the red reference (1 + eps) and averages over 3
  // channels; MAPE compares luminances and divides by the reference's
  // (not the image's).
  ImageRgb ref = uniform(1, 1, 1.f, 2.f, 0.5f), img = uniform(1, 1, 1.5f, 2.f, 0.5f);
  ImageErrors e = compare_images(img, ref);
  EXPECT_NEAR(e.rel_mse, 0.25 / (1.0 + kRelMseEpsilon) / 3.0, kTol);
  const double y_ref = luminance(1, 2, 0.5), y_img = luminance(1.5, 2, 0.5);
  EXPECT_NEAR(e.mape, (y_img - y_ref) / y_ref, kTol);
  EXPECT_GT(std::abs(e.mape - (y_img - y_ref) / y_img), 1e-3);  // the other convention would be visibly different
  EXPECT_NEAR(e.rmse, std::sqrt(0.25 / 3.0), kTol);
}

TEST(ImageMetrics, BlackReferencePixel) {
  // Two pixels: reference 1 and 0, image 1.1 and 0.2. The black pixel's
  // relMSE term is d^2 / (0 + eps) = 4, not infinite; MAPE skips it (its
  // reference luminance is 0), so MAPE is the first pixel's alone.
  ImageRgb ref = uniform(2, 1, 1.f, 1.f, 1.f), img = uniform(2, 1, 1.1f, 1.1f, 1.1f);
  set_pixel(ref, 1, 0.f, 0.f, 0.f);
  set_pixel(img, 1, 0.2f, 0.2f, 0.2f);
  ImageErrors e = compare_images(img, ref);
  const double d0 = double(1.1f) - 1.0, d1 = double(0.2f);
  EXPECT_NEAR(e.rel_mse, (d0 * d0 / (1.0 + kRelMseEpsilon) + d1 * d1 / kRelMseEpsilon) / 2.0, kTol);
  EXPECT_NEAR(e.rel_mse, (0.01 / 1.01 + 4.0) / 2.0, 1e-6);
  EXPECT_NEAR(e.mape, d0, kTol);
  EXPECT_NEAR(e.rmse, std::sqrt((d0 * d0 + d1 * d1) / 2.0), kTol);
  EXPECT_EQ(e.nonfinite_pixels, 0u);
}

TEST(ImageMetrics, AllBlackReferenceHasNoMape) {
  ImageRgb ref = uniform(2, 2, 0.f, 0.f, 0.f), img = uniform(2, 2, 0.1f, 0.1f, 0.1f);
  ImageErrors e = compare_images(img, ref);
  EXPECT_EQ(e.mape, 0.0);  // no pixel to average over: 0, not NaN
  EXPECT_NEAR(e.rel_mse, double(0.1f) * double(0.1f) / kRelMseEpsilon, kTol);
}

TEST(ImageMetrics, NonFiniteImagePixelsAreCountedAndExcluded) {
  // Pixels 1 (NaN in green) and 2 (+Inf in blue) of the image are bad; the
  // metrics are those of pixels 0 and 3 alone, as if the bad ones were absent.
  const float nan = std::numeric_limits<float>::quiet_NaN(), inf = std::numeric_limits<float>::infinity();
  ImageRgb ref = uniform(4, 1, 1.f, 1.f, 1.f), img = uniform(4, 1, 1.1f, 1.1f, 1.1f);
  set_pixel(img, 1, 1.f, nan, 1.f);
  set_pixel(img, 2, 1.f, 1.f, inf);
  set_pixel(img, 3, 1.f, 1.f, 1.f);
  ImageErrors e = compare_images(img, ref);
  EXPECT_EQ(e.nonfinite_pixels, 2u);
  EXPECT_EQ(e.reference_nonfinite_pixels, 0u);
  EXPECT_EQ(e.pixels, 4u);
  const double d = double(1.1f) - 1.0;
  EXPECT_NEAR(e.rel_mse, d * d / 1.01 / 2.0, kTol);
  EXPECT_NEAR(e.mape, d / 2.0, kTol);
  EXPECT_NEAR(e.rmse, std::sqrt(d * d / 2.0), kTol);
  EXPECT_TRUE(std::isfinite(e.mean_image[0]) && std::isfinite(e.mean_image[1]) && std::isfinite(e.mean_image[2]));
  EXPECT_NEAR(e.mean_image[1], (double(1.1f) + 1.0) / 2.0, kTol);
  // -Inf counts too.
  set_pixel(img, 0, -inf, 1.f, 1.f);
  EXPECT_EQ(compare_images(img, ref).nonfinite_pixels, 3u);
}

TEST(ImageMetrics, NonFiniteReferencePixelsAreCountedAndExcluded) {
  const float nan = std::numeric_limits<float>::quiet_NaN();
  ImageRgb ref = uniform(3, 1, 1.f, 1.f, 1.f), img = uniform(3, 1, 1.f, 1.f, 1.f);
  set_pixel(ref, 0, nan, 1.f, 1.f);
  set_pixel(img, 0, 5.f, 5.f, 5.f);  // would dominate every metric if it were counted
  set_pixel(img, 2, 1.1f, 1.1f, 1.1f);
  ImageErrors e = compare_images(img, ref);
  EXPECT_EQ(e.reference_nonfinite_pixels, 1u);
  EXPECT_EQ(e.nonfinite_pixels, 0u);
  const double d = double(1.1f) - 1.0;
  EXPECT_NEAR(e.rel_mse, d * d / 1.01 / 2.0, kTol);
  EXPECT_NEAR(e.mape, d / 2.0, kTol);
  EXPECT_NEAR(e.mean_reference[0], 1.0, kTol);

  // Bad in both at the same pixel: counted on both sides.
  set_pixel(img, 0, nan, nan, nan);
  e = compare_images(img, ref);
  EXPECT_EQ(e.nonfinite_pixels, 1u);
  EXPECT_EQ(e.reference_nonfinite_pixels, 1u);

  // Nothing finite left: metrics are 0, not NaN.
  ImageRgb all_nan = uniform(2, 1, nan, nan, nan);
  e = compare_images(all_nan, uniform(2, 1, 1.f, 1.f, 1.f));
  EXPECT_EQ(e.nonfinite_pixels, 2u);
  EXPECT_EQ(e.rel_mse, 0.0);
  EXPECT_EQ(e.mape, 0.0);
  EXPECT_EQ(e.rmse, 0.0);
}

TEST(ImageMetrics, SizeMismatchThrowsNamingBothSizes) {
  ImageRgb a = uniform(2, 3, 1.f, 1.f, 1.f), b = uniform(3, 2, 1.f, 1.f, 1.f);  // same pixel count
  try {
    compare_images(a, b);
    FAIL() << "expected std::invalid_argument";
  } catch (const std::invalid_argument& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("2x3"), std::string::npos) << msg;
    EXPECT_NE(msg.find("3x2"), std::string::npos) << msg;
  }
  EXPECT_THROW(compare_images(uniform(4, 4, 1.f, 1.f, 1.f), uniform(4, 5, 1.f, 1.f, 1.f)), std::invalid_argument);
}

// Multiplies every pixel of block (bx, by) of side `block` by s.
void scale_block(ImageRgb& img, int32_t block, int32_t bx, int32_t by, float s) {
  for (int32_t y = by * block; y < std::min(img.height, (by + 1) * block); ++y) {
    for (int32_t x = bx * block; x < std::min(img.width, (bx + 1) * block); ++x) {
      for (int c = 0; c < 3; ++c) img.rgb[3 * (static_cast<size_t>(y) * img.width + x) + c] *= s;
    }
  }
}

TEST(ImageMetrics, IdenticalImagesAgreeInEveryBlock) {
  // 20 x 12 with 8-pixel blocks: 3 x 2 blocks, the right column and bottom row partial.
  ImageRgb a = uniform(20, 12, 0.25f, 4.f, 0.5f);
  BlockAgreement b = compare_blocks(a, a);
  EXPECT_EQ(b.block, kDefaultBlockSize);
  EXPECT_EQ(b.blocks_x, 3);
  EXPECT_EQ(b.blocks_y, 2);
  EXPECT_EQ(b.judged_blocks, 6u);
  EXPECT_EQ(b.worst_ratio, 1.0);
  EXPECT_EQ(b.fraction_off, 0.0);
}

TEST(ImageMetrics, OneBrightBlockIsTheWorst) {
  // Block (2, 1) is a partial edge block (4 x 4 pixels): scaled by 1.5 it is
  // the worst, the one block of six off by more than 10 %.
  ImageRgb ref = uniform(20, 12, 1.f, 0.5f, 0.25f), img = ref;
  scale_block(img, 8, 2, 1, 1.5f);
  BlockAgreement b = compare_blocks(img, ref);
  EXPECT_NEAR(b.worst_ratio, 1.5, 1e-6);
  EXPECT_EQ(b.worst_x, 2);
  EXPECT_EQ(b.worst_y, 1);
  EXPECT_EQ(b.judged_blocks, 6u);
  EXPECT_NEAR(b.fraction_off, 1.0 / 6.0, kTol);

  // A block 5 % too dark is within tolerance and not the worst; one 20 % too
  // dark is off, but 1.5 stays the worst (|0.8 - 1| < |1.5 - 1|).
  scale_block(img, 8, 0, 0, 0.95f);
  scale_block(img, 8, 1, 0, 0.8f);
  b = compare_blocks(img, ref);
  EXPECT_NEAR(b.worst_ratio, 1.5, 1e-6);
  EXPECT_NEAR(b.fraction_off, 2.0 / 6.0, kTol);

  // Block size 4 on the same images: 5 x 3 blocks, the scaled 4 x 4 corner is one of them.
  b = compare_blocks(img, ref, 4);
  EXPECT_EQ(b.blocks_x, 5);
  EXPECT_EQ(b.blocks_y, 3);
  EXPECT_EQ(b.worst_x, 4);
  EXPECT_EQ(b.worst_y, 2);
}

TEST(ImageMetrics, DarkReferenceBlocksAreNotJudged) {
  // Reference block (1, 0) is at 1e-4 of the rest (below kBlockDarkFraction
  // of the image mean); the image is 10x brighter there, yet no block is off.
  ImageRgb ref = uniform(16, 8, 1.f, 1.f, 1.f);
  scale_block(ref, 8, 1, 0, 1e-4f);
  ImageRgb img = ref;
  scale_block(img, 8, 1, 0, 10.f);
  BlockAgreement b = compare_blocks(img, ref);
  EXPECT_EQ(b.judged_blocks, 1u);
  EXPECT_EQ(b.worst_x, 0);
  EXPECT_NEAR(b.worst_ratio, 1.0, kTol);
  EXPECT_EQ(b.fraction_off, 0.0);

  // At 1e-2 of the rest the block is bright enough to judge, and it is 10x off.
  ref = uniform(16, 8, 1.f, 1.f, 1.f);
  scale_block(ref, 8, 1, 0, 1e-2f);
  img = ref;
  scale_block(img, 8, 1, 0, 10.f);
  b = compare_blocks(img, ref);
  EXPECT_EQ(b.judged_blocks, 2u);
  EXPECT_EQ(b.worst_x, 1);
  EXPECT_NEAR(b.worst_ratio, 10.0, 1e-5);
  EXPECT_NEAR(b.fraction_off, 0.5, kTol);

  // An all-black reference leaves nothing to judge: ratio 1, no block named, not NaN.
  b = compare_blocks(uniform(16, 8, 1.f, 1.f, 1.f), uniform(16, 8, 0.f, 0.f, 0.f));
  EXPECT_EQ(b.judged_blocks, 0u);
  EXPECT_EQ(b.worst_ratio, 1.0);
  EXPECT_EQ(b.worst_x, -1);
  EXPECT_EQ(b.fraction_off, 0.0);
}

TEST(ImageMetrics, BlockMeansSkipNonFinitePixels) {
  // One NaN pixel of the image in block (0, 0), whose other pixels agree:
  // the block is judged on the rest and agrees.
  const float nan = std::numeric_limits<float>::quiet_NaN();
  ImageRgb ref = uniform(8, 8, 1.f, 1.f, 1.f), img = ref;
  set_pixel(img, 9, nan, 1.f, 1.f);
  BlockAgreement b = compare_blocks(img, ref);
  EXPECT_EQ(b.judged_blocks, 1u);
  EXPECT_EQ(b.worst_ratio, 1.0);
}

TEST(ImageMetrics, BlockComparisonRefusesBadInput) {
  EXPECT_THROW(compare_blocks(uniform(4, 4, 1.f, 1.f, 1.f), uniform(4, 5, 1.f, 1.f, 1.f)), std::invalid_argument);
  EXPECT_THROW(compare_blocks(uniform(4, 4, 1.f, 1.f, 1.f), uniform(4, 4, 1.f, 1.f, 1.f), 0), std::invalid_argument);
}

}  // namespace
}  // namespace tessera
