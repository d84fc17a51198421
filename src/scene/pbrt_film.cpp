#include "scene/pbrt_film.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "scene/named_spectra.h"

namespace tessera {
namespace {

[[noreturn]] void fail(const std::string& where, const std::string& problem) { throw SceneError(where + ": " + problem); }

// The white of the illuminant pbrt-v4's white balance starts from
// (Spectra::D): a CIE daylight of the correlated colour temperature
// kelvin * 1.4388 / 1.4380 (the old second radiation constant), or a
// blackbody below 4000 K, where the daylight series is undefined.
Vec2 illuminant_white_xy(Float kelvin) {
  const double t = kelvin * 1.4388 / 1.4380;
  if (t < 4000.0) return blackbody_xy(static_cast<Float>(t));
  const double t2 = t * t, t3 = t2 * t;
  const double x = t <= 7000. ? -4.6070e9 / t3 + 2.9678e6 / t2 + 0.09911e3 / t + 0.244063
                              : -2.0064e9 / t3 + 1.9018e6 / t2 + 0.24748e3 / t + 0.237040;
  const double y = -3.0 * x * x + 2.870 * x - 0.275;
  return Vec2(static_cast<Float>(x), static_cast<Float>(y));
}

Vec3 xyz_from_xy(Vec2 xy) { return Vec3(xy.x / xy.y, 1.f, (1.f - xy.x - xy.y) / xy.y); }

// glm matrices are column-major: build them from rows as written on paper.
Mat3 from_rows(const float r[9]) { return glm::transpose(Mat3(r[0], r[1], r[2], r[3], r[4], r[5], r[6], r[7], r[8])); }

Mat3 xyz_from_srgb() {
  static const float rows[9] = {0.412453f, 0.357580f, 0.180423f, 0.212671f, 0.715160f,
                                0.072169f, 0.019334f, 0.119193f, 0.950227f};
  return from_rows(rows);
}

}  // namespace

Mat3 white_balance_xyz(Float kelvin) {
  static const float kLmsFromXyz[9] = {0.8951f, 0.2664f, -0.1614f, -0.7502f, 1.7135f, 0.0367f, 0.0389f, -0.0685f, 1.0296f};
  const Mat3 lms_from_xyz = from_rows(kLmsFromXyz);
  const Vec3 src = lms_from_xyz * xyz_from_xy(illuminant_white_xy(kelvin));
  const Vec3 dst = lms_from_xyz * xyz_from_xy(Vec2(0.3127f, 0.3290f));  // sRGB's white, D65
  Mat3 correct(1.f);
  for (int c = 0; c < 3; ++c) correct[c][c] = dst[c] / src[c];
  return glm::inverse(lms_from_xyz) * correct * lms_from_xyz;
}

Mat3 white_balance_srgb(Float kelvin) { return glm::inverse(xyz_from_srgb()) * white_balance_xyz(kelvin) * xyz_from_srgb(); }

void set_film_sensor(FilmDesc& film, Float exposure_time) {
  const Float ratio = exposure_time * film.iso / 100.f;
  Float kelvin = film.whitebalance;
  if (film.sensor != "cie1931" && kelvin == 0.f) kelvin = 6500.f;  // pbrt-v4's default for camera sensors
  // pbrt-v4's CIE 1931 sensor records XYZ times the imaging ratio (where
  // maxcomponentvalue clamps); the film writes sRGB of the balanced XYZ.
  film.sensor_from_radiance = ratio * xyz_from_srgb();
  film.pixel_from_sensor = glm::inverse(xyz_from_srgb()) * (kelvin != 0.f ? white_balance_xyz(kelvin) : Mat3(1.f));
  film.pixel_from_radiance = kelvin != 0.f ? white_balance_srgb(kelvin) * Mat3(ratio) : Mat3(ratio);
}

namespace {

// pbrt-v4's "pixelbounds" (x0 x1 y0 y1, clamped to the image with a
// warning) or "cropwindow" (fractions, clamped to [0, 1]; not both), kept
// as fractions of the resolution (FilmDesc::crop).
template <class Warn>
void read_crop(const ParamSet& ps, const std::string& where, FilmDesc& film, Warn&& warn) {
  const Param* bounds = ps.find_any("pixelbounds");
  const Param* window = ps.find_any("cropwindow");
  if (bounds && window) fail(where, "film has both \"pixelbounds\" and \"cropwindow\"");
  // Pixel bounds x0 x1 y0 y1 at this resolution, as pbrt-v4 computes them.
  int64_t pb[4] = {0, film.xres, 0, film.yres};
  if (bounds) {
    const std::vector<int32_t>& b = ps.get_ints("pixelbounds");
    if (b.size() != 4 || bounds->type != "integer")
      fail(where, "film \"pixelbounds\" needs four integers: x0 x1 y0 y1");
    bool clamped = false;
    for (int i = 0; i < 4; ++i) {
      pb[i] = std::clamp<int64_t>(b[i], 0, i < 2 ? film.xres : film.yres);
      clamped |= pb[i] != b[i];
    }
    if (clamped) warn("film \"pixelbounds\" extend beyond the image; clamped to it");
  } else if (window) {
    const std::vector<Float> c = ps.get_floats("cropwindow");
    if (c.size() != 4) fail(where, "film \"cropwindow\" needs four numbers: x0 x1 y0 y1");
    for (Float v : c)
      if (!std::isfinite(v)) fail(where, "film \"cropwindow\" must be finite");
    // pbrt-v4: the corners ordered and clamped to [0, 1], then ceil(res * c) in float.
    const Float lo_x = std::clamp(std::min(c[0], c[1]), 0.f, 1.f), hi_x = std::clamp(std::max(c[0], c[1]), 0.f, 1.f);
    const Float lo_y = std::clamp(std::min(c[2], c[3]), 0.f, 1.f), hi_y = std::clamp(std::max(c[2], c[3]), 0.f, 1.f);
    const Float xres = static_cast<Float>(film.xres), yres = static_cast<Float>(film.yres);
    pb[0] = static_cast<int64_t>(std::ceil(xres * lo_x));
    pb[1] = static_cast<int64_t>(std::ceil(xres * hi_x));
    pb[2] = static_cast<int64_t>(std::ceil(yres * lo_y));
    pb[3] = static_cast<int64_t>(std::ceil(yres * hi_y));
  }
  if (pb[1] <= pb[0] || pb[3] <= pb[2]) fail(where, "film \"pixelbounds\"/\"cropwindow\" leave no pixels");
  for (int i = 0; i < 4; ++i) film.crop[i] = static_cast<double>(pb[i]) / (i < 2 ? film.xres : film.yres);
}

}  // namespace

PixelBounds film_pixel_bounds(const FilmDesc& film) {
  // ceil(res * fraction); the small subtraction keeps the bounds the scene
  // gave (stored as fractions) exact at its own resolution.
  auto edge = [](int32_t res, double f) { return static_cast<int32_t>(std::ceil(res * f - 1e-9)); };
  const PixelBounds pb{edge(film.xres, film.crop[0]), edge(film.yres, film.crop[2]), edge(film.xres, film.crop[1]),
                       edge(film.yres, film.crop[3])};
  if (pb.width() <= 0 || pb.height() <= 0)
    throw SceneError("the film's crop window leaves no pixels at " + std::to_string(film.xres) + "x" +
                     std::to_string(film.yres));
  return pb;
}

std::string describe_film_size(const CameraView& c) {
  std::string s = std::to_string(c.width) + "x" + std::to_string(c.height);
  if (c.film_width == c.width && c.film_height == c.height) return s;
  return s + ", pixels " + std::to_string(c.film_x0) + "-" + std::to_string(c.film_x0 + c.film_width) + " x " +
         std::to_string(c.film_y0) + "-" + std::to_string(c.film_y0 + c.film_height) + " (" +
         std::to_string(c.film_width) + "x" + std::to_string(c.film_height) + ")";
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
  read_crop(ps, where, film, warn);
}

FilterDesc read_filter(const std::string& type, const ParamSet& ps, const std::string& where,
                       std::vector<std::string>& warnings) {
  FilterDesc f;
  Float default_radius = 1.5f;
  if (type == "box") {
    f.type = FilterType::Box;
    default_radius = 0.5f;
  } else if (type == "gaussian") {
    f.type = FilterType::Gaussian;
    f.sigma = ps.get_float("sigma", 0.5f);
    if (!(f.sigma > 0.f)) fail(where, "gaussian filter \"sigma\" must be positive");
  } else if (type == "triangle") {
    f.type = FilterType::Triangle;
    default_radius = 2.f;
  } else if (type == "mitchell") {
    f.type = FilterType::Mitchell;
    default_radius = 2.f;
    f.b = ps.get_float("B", 1.f / 3.f);
    f.c = ps.get_float("C", 1.f / 3.f);
  } else if (type == "sinc") {
    f.type = FilterType::LanczosSinc;
    default_radius = 4.f;
    f.tau = ps.get_float("tau", 3.f);
    if (!(f.tau > 0.f)) fail(where, "sinc filter \"tau\" must be positive");
  } else {
    warnings.push_back(where + ": pixel filter \"" + type + "\" is unknown; using \"gaussian\"");
    ps.mark_all_used();
  }
  f.radius = ps.get_float("xradius", default_radius);
  f.radius_y = ps.get_float("yradius", default_radius);
  if (!(f.radius > 0.f) || !(f.radius_y > 0.f) || f.radius > 64.f || f.radius_y > 64.f)
    fail(where, "pixel filter radii must be in (0, 64]");
  return f;
}

Float pixel_filter_1d(const FilterDesc& f, Float x, Float radius) {
  const double ax = std::abs(static_cast<double>(x));
  if (ax > radius) return 0.f;
  switch (f.type) {
    case FilterType::Box: return 1.f;
    case FilterType::Triangle: return static_cast<Float>(radius - ax);
    case FilterType::Gaussian: {
      auto g = [&](Float v) { return std::exp(-v * v / (2.f * f.sigma * f.sigma)); };
      return std::max(0.f, g(x) - g(radius));
    }
    case FilterType::Mitchell: {
      const double t = 2.0 * ax / radius, b = f.b, c = f.c;
      if (t <= 1.0) return static_cast<Float>(((12 - 9 * b - 6 * c) * t * t * t + (-18 + 12 * b + 6 * c) * t * t + (6 - 2 * b)) / 6.0);
      return static_cast<Float>(((-b - 6 * c) * t * t * t + (6 * b + 30 * c) * t * t + (-12 * b - 48 * c) * t + (8 * b + 24 * c)) / 6.0);
    }
    case FilterType::LanczosSinc: {
      auto sinc = [](double v) { return std::abs(v) < 1e-5 ? 1.0 : std::sin(kPi * v) / (kPi * v); };
      return static_cast<Float>(sinc(ax) * sinc(ax / f.tau));
    }
  }
  return 0.f;
}

}  // namespace tessera
