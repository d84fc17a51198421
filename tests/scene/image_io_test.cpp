// Image input for textures and environment maps: the formats pbrt scenes use,
// read with pbrt-v4's orientation and colour decoding.
#include <gtest/gtest.h>

#include <OpenImageIO/imageio.h>

#include <cmath>
#include <cstring>

#include "scene/image_io.h"
#include "scene_test_helpers.h"

namespace tessera {
namespace {

using test::TempDir;

// A 2x3 PFM whose rows are stored bottom row first, as the format requires.
std::string pfm_bytes(bool grey) {
  std::string out = grey ? "Pf\n2 3\n-1.0\n" : "PF\n2 3\n-1.0\n";
  for (int stored_row = 0; stored_row < 3; ++stored_row)
    for (int x = 0; x < 2; ++x)
      for (int c = 0; c < (grey ? 1 : 3); ++c) {
        // Value encodes (row from the top, x, channel).
        const float v = 100.f * (2 - stored_row) + 10.f * x + c;
        char b[4];
        std::memcpy(b, &v, 4);
        out.append(b, 4);
      }
  return out;
}

TEST(ImageIo, PfmRowsComeOutTopFirstAndLinear) {
  TempDir dir;
  ImageDesc img = load_image(dir.write("env.pfm", pfm_bytes(false)), ColorEncoding{});
  ASSERT_EQ(img.width, 2);
  ASSERT_EQ(img.height, 3);
  for (int y = 0; y < 3; ++y)
    for (int x = 0; x < 2; ++x)
      for (int c = 0; c < 3; ++c) EXPECT_EQ(img.texels[y * 2 + x][c], 100.f * y + 10.f * x + c) << y << x << c;
  // Greyscale PFM: the one channel in all three.
  ImageDesc grey = load_image(dir.write("grey.pfm", pfm_bytes(true)), ColorEncoding{});
  EXPECT_EQ(grey.texels[5], Rgb(210.f));
}

// Writes an image of `format` through OpenImageIO (the test's own writer).
void write_image(const std::string& path, int w, int h, int channels, OIIO::TypeDesc format, const void* data) {
  std::unique_ptr<OIIO::ImageOutput> out = OIIO::ImageOutput::create(path);
  ASSERT_TRUE(out) << OIIO::geterror();
  OIIO::ImageSpec spec(w, h, channels, format);
  ASSERT_TRUE(out->open(path, spec)) << out->geterror();
  ASSERT_TRUE(out->write_image(format, data)) << out->geterror();
  out->close();
}

Float srgb_to_linear(Float v) { return v <= 0.04045f ? v / 12.92f : std::pow((v + 0.055f) / 1.055f, 2.4f); }

TEST(ImageIo, EightBitFormatsDecodeWithTheEncodingAndIgnoreAlpha) {
  TempDir dir;
  // RGBA with a transparent texel: its colour must not be premultiplied away.
  const uint8_t rgba[2 * 4] = {51, 102, 204, 0, 255, 128, 0, 255};
  for (const char* name : {"t.png", "t.tga"}) {
    SCOPED_TRACE(name);
    write_image(dir.file(name), 2, 1, 4, OIIO::TypeDesc::UINT8, rgba);
    ImageDesc srgb = load_image(dir.file(name), ColorEncoding{});
    ASSERT_EQ(srgb.width, 2);
    EXPECT_NEAR(srgb.texels[0].x, srgb_to_linear(51 / 255.f), 1e-6f);
    EXPECT_NEAR(srgb.texels[0].z, srgb_to_linear(204 / 255.f), 1e-6f);
    ImageDesc linear = load_image(dir.file(name), *parse_color_encoding("linear"));
    EXPECT_NEAR(linear.texels[0].y, 102 / 255.f, 1e-6f);
    ImageDesc gamma = load_image(dir.file(name), *parse_color_encoding("gamma 2"));
    EXPECT_NEAR(gamma.texels[1].y, std::pow(128 / 255.f, 2.f), 1e-6f);
  }
  // Grey 8-bit: the one channel in all three.
  const uint8_t grey[2] = {0, 255};
  write_image(dir.file("g.png"), 2, 1, 1, OIIO::TypeDesc::UINT8, grey);
  EXPECT_EQ(load_image(dir.file("g.png"), ColorEncoding{}).texels[1], Rgb(1.f));
}

TEST(ImageIo, SixteenBitPngDecodesWithTheEncoding) {
  TempDir dir;
  const uint16_t rgb[3] = {0, 32768, 65535};
  write_image(dir.file("t16.png"), 1, 1, 3, OIIO::TypeDesc::UINT16, rgb);
  ImageDesc img = load_image(dir.file("t16.png"), ColorEncoding{});
  EXPECT_NEAR(img.texels[0].y, srgb_to_linear(32768 / 65535.f), 1e-6f);
  EXPECT_EQ(img.texels[0].z, 1.f);
}

TEST(ImageIo, HdrIsLinear) {
  TempDir dir;
  const float rgb[3] = {4.f, 0.5f, 0.25f};
  write_image(dir.file("t.hdr"), 1, 1, 3, OIIO::TypeDesc::FLOAT, rgb);
  ImageDesc img = load_image(dir.file("t.hdr"), ColorEncoding{});
  // RGBE keeps 8 bits of mantissa per channel.
  EXPECT_NEAR(img.texels[0].x, 4.f, 4.f / 128);
  EXPECT_NEAR(img.texels[0].y, 0.5f, 4.f / 128);
}

TEST(ImageIo, UnreadableImagesAreOneLineErrors) {
  TempDir dir;
  for (const char* name : {"junk.png", "junk.pfm", "junk.tga", "missing.png"}) {
    if (std::string(name) != "missing.png") dir.write(name, "this is not an image\n");
    try {
      load_image(dir.file(name), ColorEncoding{});
      ADD_FAILURE() << name << " loaded";
    } catch (const SceneError& e) {
      const std::string msg = e.what();
      EXPECT_NE(msg.find("cannot read image '" + dir.file(name) + "'"), std::string::npos) << msg;
      EXPECT_EQ(msg.find('\n'), std::string::npos) << msg;
    }
  }
  // A truncated PFM.
  const std::string pfm = pfm_bytes(false);
  dir.write("cut.pfm", pfm.substr(0, pfm.size() - 8));
  EXPECT_THROW(load_image(dir.file("cut.pfm"), ColorEncoding{}), SceneError);
}

}  // namespace
}  // namespace tessera
