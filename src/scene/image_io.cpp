#include "scene/image_io.h"

#include <OpenImageIO/imageio.h>

#include <ImfArray.h>
#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfInputFile.h>
#include <ImfRgbaFile.h>

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <memory>
#include <optional>
#include <vector>

namespace tessera {
namespace {

std::string lower_extension(const std::string& path) {
  size_t dot = path.find_last_of('.');
  if (dot == std::string::npos) return "";
  std::string ext = path.substr(dot + 1);
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return ext;
}

// OpenImageIO's errors can span lines; our messages are one line.
std::string first_line(const std::string& text) {
  std::string line = text.substr(0, text.find('\n'));
  return line.empty() ? "unknown error" : line;
}

// 2^28 texels (3 GiB of RGB floats): larger images are refused with a message, not a bad_alloc.
constexpr int64_t kMaxImageTexels = int64_t(1) << 28;

[[noreturn]] void fail(const std::string& path, const std::string& reason) {
  throw SceneError("cannot read image '" + path + "': " + reason);
}

Float decode(Float v, const ColorEncoding& e) {
  switch (e.kind) {
    case ColorEncoding::Linear: return v;
    case ColorEncoding::Gamma: return std::pow(v, e.gamma);
    case ColorEncoding::SRGB: break;
  }
  return v <= 0.04045f ? v / 12.92f : std::pow((v + 0.055f) / 1.055f, 2.4f);
}

}  // namespace

std::optional<ImageDesc> load_exr_layer(const std::string& path, const std::array<const char*, 3>& channels) {
  try {
    Imf::InputFile file(path.c_str());
    for (const char* name : channels)
      if (!file.header().channels().findChannel(name)) return std::nullopt;
    const Imath::Box2i dw = file.header().dataWindow();
    const int w = dw.max.x - dw.min.x + 1, h = dw.max.y - dw.min.y + 1;
    ImageDesc img;
    img.width = w;
    img.height = h;
    img.path = path;
    img.texels.resize(static_cast<size_t>(w) * h);
    static_assert(sizeof(Rgb) == 3 * sizeof(float), "texels are read in place as 3 floats");
    const size_t xs = sizeof(Rgb), ys = xs * w;
    // Slices are addressed by absolute pixel coordinates: offset the base by the window's origin.
    char* base = reinterpret_cast<char*>(img.texels.data()) - dw.min.x * static_cast<ptrdiff_t>(xs) -
                 dw.min.y * static_cast<ptrdiff_t>(ys);
    Imf::FrameBuffer fb;
    for (int c = 0; c < 3; ++c) fb.insert(channels[c], Imf::Slice(Imf::FLOAT, base + c * sizeof(float), xs, ys));
    file.setFrameBuffer(fb);
    file.readPixels(dw.min.y, dw.max.y);
    return img;
  } catch (const std::exception& e) {
    fail(path, e.what());
  }
}

namespace {

ImageDesc load_exr(const std::string& path) {
  // R, G, B as 32-bit floats: OpenEXR's RGBA interface converts to half,
  // which turns values above 65504 (a sun in an environment map, a firefly
  // in a render) into Inf and rounds the rest to 11 bits.
  if (std::optional<ImageDesc> rgb = load_exr_layer(path, {"R", "G", "B"})) return std::move(*rgb);
  try {
    // Luminance/chroma files: the RGBA interface reconstructs RGB (at half precision).
    Imf::RgbaInputFile file(path.c_str());
    Imath::Box2i dw = file.dataWindow();
    const int w = dw.max.x - dw.min.x + 1, h = dw.max.y - dw.min.y + 1;
    Imf::Array2D<Imf::Rgba> pixels(h, w);
    // Shift the frame buffer so that the data window's corner lands on [0][0].
    file.setFrameBuffer(&pixels[0][0] - dw.min.x - static_cast<ptrdiff_t>(dw.min.y) * w, 1, w);
    file.readPixels(dw.min.y, dw.max.y);
    ImageDesc img;
    img.width = w;
    img.height = h;
    img.path = path;
    img.texels.resize(static_cast<size_t>(w) * h);
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        const Imf::Rgba& p = pixels[y][x];
        img.texels[static_cast<size_t>(y) * w + x] = Rgb(float(p.r), float(p.g), float(p.b));
      }
    return img;
  } catch (const std::exception& e) {
    fail(path, e.what());
  }
}

// libpng prints its own "libpng error: ..." on stderr before OpenImageIO
// reports the same problem, which becomes our one-line error: while a PNG
// is read, stderr goes to /dev/null (scenes load on one thread).
class QuietStderr {
 public:
  QuietStderr() {
    std::fflush(stderr);
    saved_ = dup(STDERR_FILENO);
    const int null = open("/dev/null", O_WRONLY | O_CLOEXEC);
    if (saved_ >= 0 && null >= 0) dup2(null, STDERR_FILENO);
    if (null >= 0) close(null);
  }
  ~QuietStderr() {
    if (saved_ < 0) return;
    dup2(saved_, STDERR_FILENO);
    close(saved_);
  }
  QuietStderr(const QuietStderr&) = delete;
  QuietStderr& operator=(const QuietStderr&) = delete;

 private:
  int saved_ = -1;
};

// Every other format pbrt scenes use (PNG, TGA, JPEG, BMP, PFM, HDR...)
// through OpenImageIO. 8- and 16-bit data are decoded with `encoding`;
// floating-point data (PFM, HDR) is linear, as pbrt-v4 reads it.
ImageDesc load_with_oiio(const std::string& path, const ColorEncoding& encoding) {
  // RGB as stored: OpenImageIO would otherwise premultiply PNG/TGA colour by alpha.
  OIIO::ImageSpec config;
  config.attribute("oiio:UnassociatedAlpha", 1);
  std::optional<QuietStderr> quiet;
  if (lower_extension(path) == "png") quiet.emplace();
  std::unique_ptr<OIIO::ImageInput> in = OIIO::ImageInput::open(path, &config);
  if (!in) fail(path, first_line(OIIO::geterror()));
  const OIIO::ImageSpec spec = in->spec();
  const int w = spec.width, h = spec.height, nc = spec.nchannels;
  if (w <= 0 || h <= 0 || nc <= 0) fail(path, "empty image");
  if (spec.depth > 1 || spec.deep) fail(path, "volume and deep images are not textures");
  if (nc > 64) fail(path, std::to_string(nc) + " channels");
  if (static_cast<int64_t>(w) * h > kMaxImageTexels) fail(path, "larger than " + std::to_string(kMaxImageTexels) + " texels");
  ImageDesc img;
  img.path = path;
  img.width = w;
  img.height = h;
  img.texels.resize(static_cast<size_t>(w) * h);
  // Grey images give grey RGB; extra channels (alpha) are dropped here.
  auto store = [&](auto&& channel_value) {
    for (size_t i = 0; i < img.texels.size(); ++i)
      for (int c = 0; c < 3; ++c) img.texels[i][c] = channel_value(i * nc + (nc >= 3 ? c : 0));
  };
  const OIIO::TypeDesc stored = spec.format;
  if (stored.is_floating_point()) {
    std::vector<float> px(img.texels.size() * nc);
    if (!in->read_image(0, 0, 0, nc, OIIO::TypeDesc::FLOAT, px.data())) fail(path, first_line(in->geterror()));
    store([&](size_t k) { return px[k]; });
  } else if (stored.size() > 1) {
    std::vector<uint16_t> px(img.texels.size() * nc);
    if (!in->read_image(0, 0, 0, nc, OIIO::TypeDesc::UINT16, px.data())) fail(path, first_line(in->geterror()));
    store([&](size_t k) { return decode(px[k] / 65535.f, encoding); });
  } else {
    std::vector<uint8_t> px(img.texels.size() * nc);
    if (!in->read_image(0, 0, 0, nc, OIIO::TypeDesc::UINT8, px.data())) fail(path, first_line(in->geterror()));
    // 256-entry table: decoding is the slow part for big textures.
    Float table[256];
    for (int v = 0; v < 256; ++v) table[v] = decode(v / 255.f, encoding);
    store([&](size_t k) { return table[px[k]]; });
  }
  return img;
}

}  // namespace

std::string ColorEncoding::name() const {
  switch (kind) {
    case Linear: return "linear";
    case Gamma: return "gamma " + std::to_string(gamma);
    case SRGB: break;
  }
  return "sRGB";
}

std::optional<ColorEncoding> parse_color_encoding(const std::string& text) {
  if (text == "sRGB" || text == "srgb") return ColorEncoding{ColorEncoding::SRGB, 2.2f};
  if (text == "linear") return ColorEncoding{ColorEncoding::Linear, 1.f};
  if (text.rfind("gamma ", 0) == 0) {
    char* end = nullptr;
    float g = std::strtof(text.c_str() + 6, &end);
    if (end != text.c_str() + 6 && *end == '\0' && g > 0.f) return ColorEncoding{ColorEncoding::Gamma, g};
  }
  return std::nullopt;
}

ImageDesc load_image(const std::string& path) { return load_image(path, ColorEncoding{}); }

ImageDesc load_image(const std::string& path, const ColorEncoding& encoding) {
  ImageDesc img = lower_extension(path) == "exr" ? load_exr(path) : load_with_oiio(path, encoding);
  if (img.width <= 0 || img.height <= 0) fail(path, "empty image");
  return img;
}

}  // namespace tessera
