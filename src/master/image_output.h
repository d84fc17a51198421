// Writing rendered images: OpenEXR (float RGB + variance layer + metadata)
// and an sRGB PNG preview.
#pragma once

#include <map>
#include <string>

#include "master/film.h"

namespace tessera {

struct ExrMetadata {
  std::map<std::string, std::string> strings;
  std::map<std::string, double> numbers;
};

// Channels R, G, B (the mean) and, when variance is given, variance.R/G/B
// (variance of the pixel mean). Throws std::runtime_error naming the path.
void write_exr(const std::string& path, const ImageRgb& mean, const ImageRgb* variance, const ExrMetadata& meta);

// Linear radiance -> sRGB 8-bit, values clamped to [0, 1] (a preview only).
void write_png_preview(const std::string& path, const ImageRgb& mean);

}  // namespace tessera
