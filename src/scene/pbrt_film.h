// pbrt-v4's Film and PixelFilter directives, and the pixel sensor the film
// models: exposure (ISO, shutter time) and white balance.
#pragma once

#include <string>
#include <vector>

#include "scene/pbrt_params.h"
#include "scene/scene_desc.h"

namespace tessera {

// Fills `film` from a Film directive. Throws SceneError (at `where`) for an
// invalid resolution, ISO or white balance.
void read_film(const std::string& type, const ParamSet& params, const std::string& where, FilmDesc& film,
               std::vector<std::string>& warnings);

// A PixelFilter directive with pbrt-v4's defaults per type.
FilterDesc read_filter(const std::string& type, const ParamSet& params, const std::string& where,
                       std::vector<std::string>& warnings);

// One axis of a separable pixel filter at offset x (pbrt-v4's definitions);
// `radius` is that axis's radius. Mitchell and windowed sinc are negative in places.
Float pixel_filter_1d(const FilterDesc& f, Float x, Float radius);

// pbrt-v4's white balance (von Kries in Bradford LMS) from a daylight
// illuminant of `kelvin` to sRGB's D65 white, as a linear sRGB -> linear sRGB matrix.
Mat3 white_balance_srgb(Float kelvin);

// Linear sRGB radiance -> the film's pixel values, as pbrt-v4's RGBFilm with
// its PixelSensor records them: imaging ratio exposure_time * ISO / 100,
// then white balance when the film asks for it (pbrt-v4: "whitebalance",
// default 0 = none for the CIE 1931 sensor, 6500 K for camera sensors).
Mat3 film_pixel_from_radiance(const FilmDesc& film, Float exposure_time);

}  // namespace tessera
