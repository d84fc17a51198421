#include "scene/pbrt_lights.h"

#include <cstdio>

#include <cmath>

#include "kernels/equal_area.h"
#include "scene/pbrt_textures.h"
#include "scene/scene_limits.h"

namespace tessera {
namespace {

Vec3 transform_point(const Mat4& m, Vec3 p) { return Vec3(m * Vec4(p, 1.f)); }

Float radians(Float degrees) { return degrees * kPi / 180.f; }

// pbrt-v4 divides by SpectrumToPhotometric(spectrum), which for an RGB value
// looks only at the colour space's illuminant: an "rgb" is used as given.
// Blackbody and named spectra are already luminance-normalised by the
// conversion to RGB, so the same holds for them.
Rgb emission(const ParamSet& params, const std::string& name) { return params.get_rgb(name).value_or(Rgb(1.f)); }

// The temperature of a "blackbody" emission parameter, 0 for anything else.
Float blackbody_kelvin(const ParamSet& params, const std::string& name) {
  const Param* p = params.find_any(name);
  return p && p->type == "blackbody" && !p->numbers.empty() ? static_cast<Float>(p->numbers[0]) : 0.f;
}

// What pbrt-v4 takes for an environment image's illuminance from the upper
// hemisphere (light space +z): the texels' luminance times cos(theta) over
// the pixels whose centre is above the horizon, times 2 pi / pixels (its
// formula, kept so that "illuminance" scales as in pbrt-v4).
double image_upper_illuminance(const ImageDesc& img) {
  double sum = 0.0;
  for (int32_t y = 0; y < img.height; ++y)
    for (int32_t x = 0; x < img.width; ++x) {
      const Vec3 w = equal_area_square_to_sphere(Vec2((x + 0.5f) / img.width, (y + 0.5f) / img.height));
      if (w.z <= 0.f) continue;
      sum += luminance(img.texels[static_cast<size_t>(y) * img.width + x]) * w.z;
    }
  return sum * 2.0 * kPi / (static_cast<double>(img.width) * img.height);
}

// pbrt-v4 refuses lights whose images hold NaN or infinite texels.
void require_finite_texels(const ImageDesc& img, const DirectiveContext& ctx) {
  for (const Rgb& t : img.texels)
    if (!std::isfinite(t.x) || !std::isfinite(t.y) || !std::isfinite(t.z))
      ctx.fail("image '" + img.path + "' has NaN or infinite texels; a light needs finite ones");
}

// pbrt-v4's infinite-light "portal": four points of a rectangle (world
// space, placed by render_from_world), emission only through its front (z = normalize(p3 - p0) x
// normalize(p1 - p0), pbrt-v4's Frame::FromXY). A portal that is not a
// rectangle (pbrt-v4's tolerance, 0.001) is refused.
void read_portal(Light& l, const std::vector<Vec3>& p, const Mat4& render_from_world, const DirectiveContext& ctx) {
  if (p.size() != 4) ctx.fail("infinite light \"portal\" needs 4 points, has " + std::to_string(p.size()));
  Vec3 w[4];
  for (int i = 0; i < 4; ++i) {
    w[i] = transform_point(render_from_world, p[i]);
    if (!std::isfinite(w[i].x) || !std::isfinite(w[i].y) || !std::isfinite(w[i].z))
      ctx.fail("infinite light \"portal\" has a non-finite point");
  }
  const Vec3 e01 = w[1] - w[0], e03 = w[3] - w[0], e12 = w[2] - w[1], e32 = w[2] - w[3];
  for (const Vec3& e : {e01, e03, e12, e32})
    if (!(glm::length(e) > 0.f)) ctx.fail("infinite light \"portal\" has coincident points");
  const Vec3 p01 = glm::normalize(e01), p03 = glm::normalize(e03), p12 = glm::normalize(e12), p32 = glm::normalize(e32);
  // Written as "not within": NaN from overflowing edges fails too.
  if (!(std::fabs(glm::dot(p01, p32) - 1.f) <= 0.001f) || !(std::fabs(glm::dot(p12, p03) - 1.f) <= 0.001f) ||
      !(std::fabs(glm::dot(p01, p12)) <= 0.001f) || !(std::fabs(glm::dot(p03, p32)) <= 0.001f) ||
      !(glm::length(glm::cross(e01, e03)) < kInfinity))
    ctx.fail("infinite light \"portal\" is not a rectangle (points in order around it)");
  l.portal_p0 = w[0];
  l.portal_s = e01;
  l.portal_t = e03;
  l.portal_n = glm::normalize(glm::cross(p03, p01));
  l.portal_area = glm::length(glm::cross(e01, e03));
}

// Light paths start at a light's position (Embree takes no ray from beyond
// 1.8e18), and pbrt-v4's I / d^2 overflows to black past 1.8e19: a light
// is placed as a vertex is (scene_limits.h). A direction from "from" to "to"
// that overflows single precision, or an emission that does, gives nothing
// meaningful in pbrt-v4 either.
// The largest radiance a light may emit where a camera ray can see it: a
// pixel sums its samples in single precision and the sensor's matrix mixes
// the channels, so brighter ones make Inf pixels (the variance layer
// saturates well below that, by design).
// (Point-like lights are divided by the squared distance first: their
// intensity is limited by what float holds.)
constexpr Float kMaxRadiance = 1e32f;

void check_radiance_limit(const Rgb& L, const char* what, const DirectiveContext& ctx) {
  if (max_component(glm::abs(L)) > kMaxRadiance) {
    char value[32];
    std::snprintf(value, sizeof value, "%g", static_cast<double>(max_component(glm::abs(L))));
    ctx.fail(std::string(what) + " is " + value + ", beyond 1e+32: a pixel's sums would overflow single precision");
  }
}

void check_light_limits(const Light& l, const DirectiveContext& ctx) {
  if (l.type != LightType::Distant && l.type != LightType::Infinite && !representable(l.position))
    ctx.fail("the light is " + describe_far(l.position, ctx.scene.render_origin));
  if (!(glm::length(l.direction) > 0.5f))
    ctx.fail("the light's direction from \"from\" to \"to\" overflows single precision");
  if (!is_finite(l.L)) ctx.fail("the light's emission (times \"scale\" and \"power\") is not finite");
  if (l.type == LightType::Infinite || l.type == LightType::Distant)
    check_radiance_limit(l.L, "the light's radiance (times \"scale\" and \"power\")", ctx);
}

}  // namespace

std::optional<Light> make_light(const std::string& type, const ParamSet& params, const Mat4& world_from_light,
                                const Mat4& render_from_world,
                                const DirectiveContext& ctx) {
  Light l;
  const Float scale = params.get_float("scale", 1.f);
  if (type == "point") {
    l.type = LightType::Point;
    l.L = emission(params, "I") * scale;
    l.blackbody_kelvin = blackbody_kelvin(params, "I");
    // pbrt-v4: power sets the scale so that a white I emits `power`; the RGB
    // colour itself is not taken into account.
    if (Float power = params.get_float("power", -1.f); power > 0.f) l.L *= power / (4.f * kPi);
    l.position = transform_point(world_from_light, params.get_point3("from").value_or(Vec3(0.f)));
  } else if (type == "spot") {
    l.type = LightType::Spot;
    l.L = emission(params, "I") * scale;
    l.blackbody_kelvin = blackbody_kelvin(params, "I");
    const Float cone = params.get_float("coneangle", 30.f), delta = params.get_float("conedeltaangle", 5.f);
    l.cos_falloff_end = std::cos(radians(cone));
    l.cos_falloff_start = std::cos(radians(cone - delta));
    if (Float power = params.get_float("power", -1.f); power > 0.f) {
      Float k_e = 2.f * kPi * ((1.f - l.cos_falloff_start) + (l.cos_falloff_start - l.cos_falloff_end) / 2.f);
      l.L *= power / k_e;
    }
    Vec3 from = params.get_point3("from").value_or(Vec3(0.f)), to = params.get_point3("to").value_or(Vec3(0.f, 0.f, 1.f));
    if (from == to) ctx.fail("spot light \"from\" and \"to\" coincide");
    l.position = transform_point(world_from_light, from);
    l.direction = glm::normalize(Mat3(world_from_light) * (to - from));
  } else if (type == "goniometric") {
    // A point light at the light frame's origin whose intensity is I times a
    // grey equal-area image over directions (pbrt-v4 reads it with y and z
    // swapped: the image's pole is the frame's +y).
    l.type = LightType::Goniometric;
    l.L = emission(params, "I") * scale;
    l.blackbody_kelvin = blackbody_kelvin(params, "I");
    const std::string filename = params.get_string("filename", "");
    double mean = 1.0;
    if (filename.empty()) {
      ctx.warn("goniometric light without \"filename\": it emits I in every direction");
    } else {
      l.image = image_index(filename, "sRGB", true, ctx);
      const ImageDesc& img = ctx.scene.images[l.image];
      if (img.width != img.height)
        ctx.fail("goniometric light image '" + img.path + "' is " + std::to_string(img.width) + "x" +
                 std::to_string(img.height) + "; it must be square (equal-area octahedral)");
      require_finite_texels(img, ctx);
      mean = 0.0;
      for (const Rgb& t : img.texels) mean += t.x;
      mean /= static_cast<double>(img.texels.size());
    }
    if (Float power = params.get_float("power", -1.f); power > 0.f && mean > 0.0)
      l.L *= static_cast<Float>(power / (4.0 * kPi * mean));
    l.position = transform_point(world_from_light, Vec3(0.f));
    const Mat3 swap_yz(1.f, 0.f, 0.f, 0.f, 0.f, 1.f, 0.f, 1.f, 0.f);
    l.light_from_world = swap_yz * glm::inverse(Mat3(world_from_light));
  } else if (type == "projection") {
    // A slide projector at the light frame's origin looking down +z: the
    // image through a perspective window of "fov" (pbrt-v4 flips the frame's y).
    l.type = LightType::Projection;
    const std::string filename = params.get_string("filename", "");
    if (filename.empty()) ctx.fail("projection light needs \"string filename\"");
    l.image = image_index(filename, "sRGB", false, ctx);
    const ImageDesc& img = ctx.scene.images[l.image];
    require_finite_texels(img, ctx);
    const Float fov = params.get_float("fov", 90.f);
    if (!(fov > 0.f && fov < 180.f)) ctx.fail("projection light \"fov\" must be in (0, 180) degrees");
    const Float aspect = static_cast<Float>(img.width) / static_cast<Float>(img.height);
    l.screen_max = aspect > 1.f ? Vec2(aspect, 1.f) : Vec2(1.f, 1.f / aspect);
    l.tan_half_fov = std::tan(radians(fov) * 0.5f);
    l.L = Rgb(scale);
    if (Float power = params.get_float("power", -1.f); power > 0.f) {
      // pbrt-v4: the window's area times the texels' mean luminance x cos^3.
      const double area = 4.0 * double(l.tan_half_fov) * l.tan_half_fov * (aspect > 1.f ? aspect : 1.f / aspect);
      double sum = 0.0;
      for (int32_t y = 0; y < img.height; ++y)
        for (int32_t x = 0; x < img.width; ++x) {
          const Vec2 ps(-l.screen_max.x + 2.f * l.screen_max.x * (x + 0.5f) / img.width,
                        -l.screen_max.y + 2.f * l.screen_max.y * (y + 0.5f) / img.height);
          const double cos_t = glm::normalize(Vec3(ps * l.tan_half_fov, 1.f)).z;
          sum += luminance(img.texels[static_cast<size_t>(y) * img.width + x]) * cos_t * cos_t * cos_t;
        }
      const double k_e = area * sum / (static_cast<double>(img.width) * img.height);
      if (k_e > 0.0) l.L *= static_cast<Float>(power / k_e);
    }
    l.position = transform_point(world_from_light, Vec3(0.f));
    const Mat3 flip_y(1.f, 0.f, 0.f, 0.f, -1.f, 0.f, 0.f, 0.f, 1.f);
    l.light_from_world = flip_y * glm::inverse(Mat3(world_from_light));
  } else if (type == "distant") {
    l.type = LightType::Distant;
    l.L = emission(params, "L") * scale;
    l.blackbody_kelvin = blackbody_kelvin(params, "L");
    if (Float e = params.get_float("illuminance", -1.f); e > 0.f) l.L *= e;
    Vec3 from = params.get_point3("from").value_or(Vec3(0.f)), to = params.get_point3("to").value_or(Vec3(0.f, 0.f, 1.f));
    if (from == to) ctx.fail("distant light \"from\" and \"to\" coincide");
    l.direction = glm::normalize(Mat3(world_from_light) * (from - to));
  } else if (type == "infinite") {
    l.type = LightType::Infinite;
    const bool has_l = params.find_any("L") != nullptr;
    std::string filename = params.get_string("filename", "");
    if (has_l && !filename.empty()) ctx.fail("infinite light takes either \"L\" or \"filename\", not both");
    if (!filename.empty()) {
      l.image = image_index(filename, params.get_string("encoding", "sRGB"), false, ctx);
      const ImageDesc& img = ctx.scene.images[l.image];
      if (img.width != img.height)
        ctx.fail("infinite light image '" + img.path + "' is " + std::to_string(img.width) + "x" +
                 std::to_string(img.height) + "; it must be square (equal-area octahedral)");
      require_finite_texels(img, ctx);
      l.L = Rgb(scale);
    } else {
      l.L = emission(params, "L") * scale;
      l.blackbody_kelvin = blackbody_kelvin(params, "L");
    }
    const Float illuminance = params.get_float("illuminance", -1.f);
    if (illuminance > 0.f) {
      const double k_e = l.image >= 0 ? image_upper_illuminance(ctx.scene.images[l.image]) : kPi;
      if (k_e > 0.0) l.L *= static_cast<Float>(illuminance / k_e);
    }
    if (params.find_any("portal")) read_portal(l, params.get_point3s("portal"), render_from_world, ctx);
    l.light_from_world = glm::inverse(Mat3(world_from_light));
  } else {
    ctx.warn("light \"" + type + "\" is not supported; skipped");
    params.mark_all_used();
    return std::nullopt;
  }
  check_light_limits(l, ctx);
  return l;
}

AreaLightDesc make_area_light(const std::string& type, const ParamSet& params, const DirectiveContext& ctx) {
  if (type != "diffuse") ctx.warn("area light \"" + type + "\" is not supported; using \"diffuse\"");
  AreaLightDesc a;
  const Float scale = params.get_float("scale", 1.f);
  a.L = emission(params, "L") * scale;
  a.blackbody_kelvin = blackbody_kelvin(params, "L");
  a.two_sided = params.get_bool("twosided", false);
  const std::string filename = params.get_string("filename", "");
  if (!filename.empty()) {
    if (params.find_any("L")) ctx.fail("area light takes either \"L\" or \"filename\", not both");
    // pbrt-v4 reads the file in its own encoding (8-bit files are sRGB).
    a.image = image_index(filename, "sRGB", false, ctx);
    require_finite_texels(ctx.scene.images[a.image], ctx);
    a.L = Rgb(scale);
  }
  if (!is_finite(a.L)) ctx.fail("area light \"L\" times \"scale\" is not finite");
  check_radiance_limit(a.L, "area light \"L\" times \"scale\"", ctx);
  const Float power = params.get_float("power", -1.f);
  if (!std::isfinite(power)) ctx.fail("area light \"power\" must be finite");
  a.power = power > 0.f ? power : 0.f;  // pbrt-v4: only a positive power rescales
  return a;
}

}  // namespace tessera
