#include "render/image_output.h"

#include <OpenEXR/ImfChannelList.h>
#include <OpenEXR/ImfDoubleAttribute.h>
#include <OpenEXR/ImfFrameBuffer.h>
#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfInputFile.h>
#include <OpenEXR/ImfOutputFile.h>
#include <OpenEXR/ImfStringAttribute.h>
#include <stb/stb_image_write.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <vector>

#include "render/renderer.h"
#include "scene/image_io.h"

namespace tessera {

void add_render_metadata(ExrMetadata* meta, const RenderStats& s) {
  meta->numbers["spp"] = s.spp;
  meta->numbers["seconds"] = s.seconds;
  meta->numbers["ranks"] = s.ranks;
  if (s.estimated_rel_mse >= 0) meta->numbers["estimated_relmse"] = s.estimated_rel_mse;
  if (s.target_error > 0) meta->numbers["target_error"] = s.target_error;
  if (!s.stop_reason.empty()) meta->strings["stop_reason"] = s.stop_reason;
  meta->strings["guide"] = s.guide_mode;
}

uint64_t add_variance_metadata(ExrMetadata* meta, const ImageRgb& variance) {
  const uint64_t saturated = variance_saturated_pixels(variance);
  if (saturated) meta->numbers["variance_saturated_pixels"] = static_cast<double>(saturated);
  return saturated;
}

void write_exr(const std::string& path, const ImageRgb& mean, const ImageRgb* variance, const ExrMetadata& meta) {
  try {
    Imf::Header header(mean.width, mean.height);
    const char* names[3] = {"R", "G", "B"};
    const char* var_names[3] = {"variance.R", "variance.G", "variance.B"};
    for (int c = 0; c < 3; ++c) header.channels().insert(names[c], Imf::Channel(Imf::FLOAT));
    if (variance)
      for (int c = 0; c < 3; ++c) header.channels().insert(var_names[c], Imf::Channel(Imf::FLOAT));
    for (const auto& [k, v] : meta.strings) header.insert(k, Imf::StringAttribute(v));
    for (const auto& [k, v] : meta.numbers) header.insert(k, Imf::DoubleAttribute(v));
    Imf::FrameBuffer fb;
    const size_t xs = 3 * sizeof(float), ys = xs * mean.width;
    for (int c = 0; c < 3; ++c) {
      fb.insert(names[c], Imf::Slice(Imf::FLOAT, (char*)(mean.rgb.data() + c), xs, ys));
      if (variance) fb.insert(var_names[c], Imf::Slice(Imf::FLOAT, (char*)(variance->rgb.data() + c), xs, ys));
    }
    Imf::OutputFile file(path.c_str(), header);
    file.setFrameBuffer(fb);
    file.writePixels(mean.height);
  } catch (const std::exception& e) {
    throw std::runtime_error("cannot write " + path + ": " + e.what());
  }
}

ImageRgb to_image_rgb(const ImageDesc& d) {
  ImageRgb img{d.width, d.height, std::vector<float>(d.texels.size() * 3)};
  for (size_t i = 0; i < d.texels.size(); ++i)
    for (int c = 0; c < 3; ++c) img.rgb[3 * i + c] = d.texels[i][c];
  return img;
}

std::optional<ImageRgb> read_exr_variance(const std::string& path) {
  std::optional<ImageDesc> var = load_exr_layer(path, {"variance.R", "variance.G", "variance.B"});
  if (!var) return std::nullopt;
  return to_image_rgb(*var);
}

std::optional<double> read_exr_number(const std::string& path, const std::string& name) {
  try {
    Imf::InputFile file(path.c_str());
    if (const auto* a = file.header().findTypedAttribute<Imf::DoubleAttribute>(name)) return a->value();
    return std::nullopt;
  } catch (const std::exception& e) {
    throw std::runtime_error("cannot read " + path + ": " + e.what());
  }
}

void write_png_preview(const std::string& path, const ImageRgb& mean) {
  std::vector<unsigned char> px(mean.rgb.size());
  for (size_t i = 0; i < mean.rgb.size(); ++i) {
    float v = mean.rgb[i];
    if (!(v > 0.f)) v = 0.f;
    v = v <= 0.0031308f ? 12.92f * v : 1.055f * std::pow(v, 1.f / 2.4f) - 0.055f;
    px[i] = static_cast<unsigned char>(std::clamp(v, 0.f, 1.f) * 255.f + 0.5f);
  }
  if (!stbi_write_png(path.c_str(), mean.width, mean.height, 3, px.data(), mean.width * 3)) {
    throw std::runtime_error("cannot write " + path);
  }
}

}  // namespace tessera
