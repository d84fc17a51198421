// pbrt-v4's Film and PixelFilter directives, and the pixel sensor the film
// models: exposure (ISO, shutter time) and white balance.
#pragma once

#include <string>
#include <vector>

#include "scene/pbrt_params.h"
#include "kernels/scene_view.h"
#include "scene/scene_desc.h"

namespace tessera {

// Fills `film` from a Film directive. Throws SceneError (at `where`) for an
// invalid resolution, ISO or white balance.
void read_film(const std::string& type, const ParamSet& params, const std::string& where, FilmDesc& film,
               std::vector<std::string>& warnings);

// The pixels the film's crop covers at its resolution. Throws SceneError
// when they are none (a resolution changed after loading can do that).
PixelBounds film_pixel_bounds(const FilmDesc& film);

// "640x480", or with a crop "640x480, pixels 100-300 x 50-150 (200x100)".
std::string describe_film_size(const CameraView& camera);

// A PixelFilter directive with pbrt-v4's defaults per type.
FilterDesc read_filter(const std::string& type, const ParamSet& params, const std::string& where,
                       std::vector<std::string>& warnings);

// One axis of a separable pixel filter at offset x (pbrt-v4's definitions);
// `radius` is that axis's radius. Mitchell and windowed sinc are negative in places.
Float pixel_filter_1d(const FilterDesc& f, Float x, Float radius);

// pbrt-v4's white balance (von Kries in Bradford LMS) from the white of the
// illuminant pbrt-v4 names by `kelvin` (daylight, a blackbody below 4000 K)
// to sRGB's D65 white: as an XYZ -> XYZ matrix, and as linear sRGB -> linear sRGB.
Mat3 white_balance_xyz(Float kelvin);
Mat3 white_balance_srgb(Float kelvin);

// Sets the film's sensor matrices (FilmDesc::sensor_from_radiance,
// pixel_from_sensor, pixel_from_radiance) as pbrt-v4's RGBFilm with its
// PixelSensor records radiance: XYZ times the imaging ratio exposure_time *
// ISO / 100 in the sensor, then white balance when the film asks for it
// (pbrt-v4: "whitebalance", default 0 = none for the CIE 1931 sensor, 6500 K
// for camera sensors) and XYZ -> sRGB on output.
void set_film_sensor(FilmDesc& film, Float exposure_time);

}  // namespace tessera
