#include "scene/pbrt_film.h"

#include <cmath>
#include <limits>

namespace tessera {
namespace {

[[noreturn]] void fail(const std::string& where, const std::string& problem) { throw SceneError(where + ": " + problem); }

// CIE daylight locus: the chromaticity of the D illuminant at `kelvin`
// (the curve pbrt-v4's Spectra::D is built on).
Vec2 daylight_xy(double kelvin) {
  const double t = kelvin, t2 = t * t, t3 = t2 * t;
  const double x = t <= 7000. ? -4.6070e9 / t3 + 2.9678e6 / t2 + 0.09911e3 / t + 0.244063
                              : -2.0064e9 / t3 + 1.9018e6 / t2 + 0.24748e3 / t + 0.237040;
  const double y = -3.0 * x * x + 2.870 * x - 0.275;
  return Vec2(static_cast<Float>(x), static_cast<Float>(y));
}

Vec3 xyz_from_xy(Vec2 xy) { return Vec3(xy.x / xy.y, 1.f, (1.f - xy.x - xy.y) / xy.y); }

// glm matrices are column-major: build them from rows as written on paper.
Mat3 from_rows(const float r[9]) { return glm::transpose(Mat3(r[0], r[1], r[2], r[3], r[4], r[5], r[6], r[7], r[8])); }

}  // namespace

Mat3 white_balance_srgb(Float kelvin) {
  static const float kLmsFromXyz[9] = {0.8951f, 0.2664f, -0.1614f, -0.7502f, 1.7135f, 0.0367f, 0.0389f, -0.0685f, 1.0296f};
  static const float kXyzFromSrgb[9] = {0.412453f, 0.357580f, 0.180423f, 0.212671f, 0.715160f,
                                        0.072169f, 0.019334f, 0.119193f, 0.950227f};
  const Mat3 lms_from_xyz = from_rows(kLmsFromXyz), xyz_from_srgb = from_rows(kXyzFromSrgb);
  const Vec3 src = lms_from_xyz * xyz_from_xy(daylight_xy(kelvin));
  const Vec3 dst = lms_from_xyz * xyz_from_xy(Vec2(0.3127f, 0.3290f));  // sRGB's white, D65
  Mat3 correct(1.f);
  for (int c = 0; c < 3; ++c) correct[c][c] = dst[c] / src[c];
  const Mat3 xyz_balance = glm::inverse(lms_from_xyz) * correct * lms_from_xyz;
  return glm::inverse(xyz_from_srgb) * xyz_balance * xyz_from_srgb;
}

Mat3 film_pixel_from_radiance(const FilmDesc& film, Float exposure_time) {
  Mat3 m(exposure_time * film.iso / 100.f);
  Float kelvin = film.whitebalance;
  if (film.sensor != "cie1931" && kelvin == 0.f) kelvin = 6500.f;  // pbrt-v4's default for camera sensors
  if (kelvin != 0.f) m = white_balance_srgb(kelvin) * m;
  return m;
}

void read_film(const std::string& type, const ParamSet& ps, const std::string& where, FilmDesc& film,
               std::vector<std::string>& warnings) {
  auto warn = [&](const std::string& m) { warnings.push_back(where + ": " + m); };
  if (type != "rgb" && type != "gbuffer" && type != "spectral") warn("film \"" + type + "\" treated as \"rgb\"");
  film.xres = ps.get_int("xresolution", 1280);
  film.yres = ps.get_int("yresolution", 720);
  film.filename = ps.get_string("filename", film.filename);
  if (film.xres <= 0 || film.yres <= 0) fail(where, "film resolution must be positive");
  if (film.xres > kMaxFilmDimension || film.yres > kMaxFilmDimension ||
      int64_t(film.xres) * film.yres > kMaxFilmPixels)
    fail(where, "film resolution " + std::to_string(film.xres) + "x" + std::to_string(film.yres) +
                    " is larger than supported (" + std::to_string(kMaxFilmPixels) + " pixels)");
  film.iso = ps.get_float("iso", 100.f);
  if (!(film.iso > 0.f) || !std::isfinite(film.iso)) fail(where, "film \"iso\" must be positive");
  film.whitebalance = ps.get_float("whitebalance", 0.f);
  if (film.whitebalance != 0.f && !(film.whitebalance >= 1000.f && film.whitebalance <= 25000.f))
    fail(where, "film \"whitebalance\" must be 0 (none) or a temperature in 1000..25000 K");
  film.sensor = ps.get_string("sensor", "cie1931");
  if (film.sensor != "cie1931")
    warn("sensor \"" + film.sensor +
         "\": its spectral response is not modelled; recorded as the CIE 1931 observer with its exposure and white balance");
  film.max_component_value = ps.get_float("maxcomponentvalue", std::numeric_limits<Float>::infinity());
  if (!(film.max_component_value > 0.f)) fail(where, "film \"maxcomponentvalue\" must be positive");
  for (const char* ignored : {"savefp16", "diagonal"}) ps.find_any(ignored);
  for (const char* unsupported : {"cropwindow", "pixelbounds"})
    if (ps.find_any(unsupported)) warn(std::string("film \"") + unsupported + "\" is not supported; the whole image is rendered");
}

FilterDesc read_filter(const std::string& type, const ParamSet& ps, const std::string& where,
                       std::vector<std::string>& warnings) {
  FilterDesc f;
  if (type == "box") {
    f.type = FilterType::Box;
    f.radius = ps.get_float("xradius", 0.5f);
    ps.get_float("yradius", f.radius);
  } else {
    if (type != "gaussian") {
      warnings.push_back(where + ": pixel filter \"" + type + "\" is not supported; using \"gaussian\"");
      ps.mark_all_used();
    }
    f.type = FilterType::Gaussian;
    f.radius = ps.get_float("xradius", 1.5f);
    ps.get_float("yradius", f.radius);
    f.sigma = ps.get_float("sigma", 0.5f);
  }
  return f;
}

}  // namespace tessera
