// Writing rendered images: OpenEXR (float RGB + variance layer + metadata)
// and an sRGB PNG preview.
#pragma once

#include <map>
#include <optional>
#include <string>

#include "render/film.h"
#include "scene/scene_desc.h"

namespace tessera {

struct RenderStats;  // render/renderer.h

struct ExrMetadata {
  std::map<std::string, std::string> strings;
  std::map<std::string, double> numbers;
};

// What a render's image records about how it was made: samples, time,
// stop reason, estimated relMSE (and the target asked for), guide mode.
void add_render_metadata(ExrMetadata* meta, const RenderStats& stats);
// variance_saturated_pixels, where the variance layer has any (film.h);
// returns their number.
uint64_t add_variance_metadata(ExrMetadata* meta, const ImageRgb& variance);

// Channels R, G, B (the mean) and, when variance is given, variance.R/G/B
// (variance of the pixel mean). Throws std::runtime_error naming the path.
void write_exr(const std::string& path, const ImageRgb& mean, const ImageRgb* variance, const ExrMetadata& meta);

// An image as loaded (scene/image_io.h) as the RGB floats metrics work on.
ImageRgb to_image_rgb(const ImageDesc& image);

// The variance layer of an EXR written by write_exr; nullopt when the file
// has none. Throws SceneError naming the path if it cannot be read.
std::optional<ImageRgb> read_exr_variance(const std::string& path);

// A numeric header attribute of an EXR (e.g. "spp"); nullopt when absent.
std::optional<double> read_exr_number(const std::string& path, const std::string& name);

// Linear radiance -> sRGB 8-bit, values clamped to [0, 1] (a preview only).
void write_png_preview(const std::string& path, const ImageRgb& mean);

}  // namespace tessera
