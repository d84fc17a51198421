#include "scene/pbrt_textures.h"

#include <algorithm>
#include <cmath>
#include <filesystem>

#include "scene/image_io.h"
#include "scene/pbrt_paths.h"

namespace tessera {
namespace {

// Adds the texture; one that nests deeper than the kernels evaluate is an
// error here, not a stack overflow at render time.
int32_t add_texture(const DirectiveContext& ctx, const Texture& t) {
  std::vector<int32_t>& depth = ctx.names.texture_depth;
  int32_t d = 1;
  for (const TextureSlot* slot : {&t.a, &t.b, &t.amount})
    if (slot->texture >= 0 && static_cast<size_t>(slot->texture) < depth.size())
      d = std::max(d, depth[static_cast<size_t>(slot->texture)] + 1);
  if (d > kMaxTextureNesting)
    ctx.fail("texture nests " + std::to_string(d) + " textures deep; at most " + std::to_string(kMaxTextureNesting) +
             " are supported");
  depth.resize(ctx.scene.textures.size(), 1);
  depth.push_back(d);
  ctx.scene.textures.push_back(t);
  return static_cast<int32_t>(ctx.scene.textures.size() - 1);
}

// The texture's space seen from render space: the inverse of the CTM at the
// Texture directive (pbrt-v4's textureFromRender), needed by every mapping
// but uv.
Mat4 texture_from_render(const glm::dmat4& render_from_texture, const DirectiveContext& ctx) {
  const Mat4 m(glm::inverse(render_from_texture));
  for (int c = 0; c < 4; ++c)
    for (int r = 0; r < 4; ++r)
      if (!std::isfinite(m[c][r])) ctx.fail("the texture's transformation is singular; its mapping needs its inverse");
  return m;
}

// pbrt-v4's TextureMapping2D::Create: "uv" (uscale, vscale, udelta, vdelta),
// "spherical", "cylindrical" or "planar" (v1, v2, udelta, vdelta).
void read_mapping_2d(Texture& t, const ParamSet& params, const glm::dmat4& render_from_texture,
                     const DirectiveContext& ctx) {
  const std::string mapping = params.get_string("mapping", "uv");
  if (mapping == "spherical" || mapping == "cylindrical" || mapping == "planar") {
    t.mapping = mapping == "spherical"     ? TextureMapping::Spherical
                : mapping == "cylindrical" ? TextureMapping::Cylindrical
                                           : TextureMapping::Planar;
    t.texture_from_render = texture_from_render(render_from_texture, ctx);
    if (t.mapping == TextureMapping::Planar) {
      t.vs = params.get_point3("v1").value_or(Vec3(1.f, 0.f, 0.f));
      t.vt = params.get_point3("v2").value_or(Vec3(0.f, 1.f, 0.f));
      t.du = params.get_float("udelta", 0.f);
      t.dv = params.get_float("vdelta", 0.f);
    }
    return;
  }
  if (mapping != "uv") ctx.warn("2D texture mapping \"" + mapping + "\" unknown; using \"uv\" (as pbrt-v4 does)");
  t.su = params.get_float("uscale", 1.f);
  t.sv = params.get_float("vscale", 1.f);
  t.du = params.get_float("udelta", 0.f);
  t.dv = params.get_float("vdelta", 0.f);
}

// pbrt-v4's TextureMapping3D: the point in the texture's space.
void set_mapping_3d(Texture& t, const glm::dmat4& render_from_texture, const DirectiveContext& ctx) {
  t.mapping = TextureMapping::Point3D;
  t.texture_from_render = texture_from_render(render_from_texture, ctx);
}

// "octaves" and "roughness" of the noise textures. Octaves past 32 have
// frequencies beyond float resolution at any useful scale: clamped.
void read_octaves(Texture& t, const ParamSet& params, const DirectiveContext& ctx) {
  constexpr int kMaxOctaves = 32;
  const int octaves = params.get_int("octaves", 8);
  if (octaves < 0) ctx.fail("\"octaves\" must not be negative, got " + std::to_string(octaves));
  if (octaves > kMaxOctaves)
    ctx.warn("\"octaves\" " + std::to_string(octaves) + " clamped to " + std::to_string(kMaxOctaves) +
             " (finer octaves are below float resolution)");
  t.octaves = std::min(octaves, kMaxOctaves);
  t.omega = params.get_float("roughness", 0.5f);
}

// A texture parameter that may be a value or a texture name, of either kind.
TextureSlot any_slot(const ParamSet& params, const std::string& name, bool spectrum, Rgb fallback,
                     const DirectiveContext& ctx) {
  return spectrum ? spectrum_slot(params, name, fallback, ctx) : float_slot(params, name, fallback.x, ctx);
}

// An image texture's "wrap" and "filter", with pbrt-v4's names; pbrt-v4
// refuses unknown ones. Without ray differentials every filter but "point"
// reads the finest level bilinearly (pbrt-v4's choice for a zero footprint).
void read_image_lookup(Texture& t, const ParamSet& params, const DirectiveContext& ctx) {
  const std::string wrap = params.get_string("wrap", "repeat");
  if (wrap == "repeat") t.wrap = ImageWrap::Repeat;
  else if (wrap == "black") t.wrap = ImageWrap::Black;
  else if (wrap == "clamp") t.wrap = ImageWrap::Clamp;
  else if (wrap == "octahedralsphere") t.wrap = ImageWrap::OctahedralSphere;
  else ctx.fail("texture wrap mode \"" + wrap + "\" unknown (repeat, black, clamp or octahedralsphere)");
  const std::string filter = params.get_string("filter", "bilinear");
  if (filter == "point") t.filter = ImageFilter::Point;
  else if (filter == "bilinear" || filter == "trilinear" || filter == "ewa" || filter == "EWA") t.filter = ImageFilter::Bilinear;
  else ctx.fail("texture filter \"" + filter + "\" unknown (point, bilinear, trilinear or ewa)");
  params.get_float("maxanisotropy", 8.f);
}

}  // namespace

int32_t image_index(const std::string& filename, const std::string& encoding_name, bool grey,
                    const DirectiveContext& ctx) {
  std::string path = resolve_scene_path(filename, ctx.including_dir, ctx.search_dir);
  ctx.scene.files_read.push_back(path);
  std::error_code ec;
  if (!std::filesystem::exists(path, ec)) ctx.fail("image file '" + path + "' not found");
  std::optional<ColorEncoding> encoding = parse_color_encoding(encoding_name);
  if (!encoding) {
    ctx.warn("unknown color encoding \"" + encoding_name + "\"; using sRGB");
    encoding = ColorEncoding{};
  }
  const std::string key = path + "|" + encoding->name() + (grey ? "|grey" : "");
  auto found = ctx.names.images.find(key);
  if (found != ctx.names.images.end()) return found->second;
  ImageDesc img;
  try {
    img = load_image(path, *encoding);
  } catch (const SceneError& e) {
    ctx.fail(e.what());
  }
  // Float textures read the channel average, as pbrt-v4 does for RGB images.
  if (grey)
    for (Rgb& t : img.texels) t = Rgb((t.x + t.y + t.z) / 3.f);
  ctx.scene.images.push_back(std::move(img));
  const int32_t index = static_cast<int32_t>(ctx.scene.images.size() - 1);
  ctx.names.images[key] = index;
  return index;
}

TextureSlot spectrum_slot(const ParamSet& params, const std::string& name, Rgb fallback, const DirectiveContext& ctx) {
  if (auto tex = params.get_texture(name)) {
    // A float texture where a spectrum is expected reads as grey.
    for (const auto* table : {&ctx.names.spectrum_textures, &ctx.names.float_textures}) {
      auto it = table->find(*tex);
      if (it != table->end()) return TextureSlot{it->second, Rgb(0.f)};
    }
    ctx.fail("unknown texture \"" + *tex + "\" for parameter '" + name + "'");
  }
  if (auto rgb = params.get_rgb(name)) return TextureSlot{-1, *rgb};
  return TextureSlot{-1, fallback};
}

TextureSlot float_slot(const ParamSet& params, const std::string& name, Float fallback, const DirectiveContext& ctx) {
  if (auto tex = params.get_texture(name)) {
    auto it = ctx.names.float_textures.find(*tex);
    if (it == ctx.names.float_textures.end()) ctx.fail("unknown float texture \"" + *tex + "\" for parameter '" + name + "'");
    return TextureSlot{it->second, Rgb(0.f)};
  }
  return TextureSlot{-1, Rgb(params.get_float(name, fallback))};
}

Float constant_float(const ParamSet& params, const std::string& name, Float fallback, const DirectiveContext& ctx) {
  TextureSlot s = float_slot(params, name, fallback, ctx);
  if (s.texture < 0) return s.value.x;
  const Texture& t = ctx.scene.textures[s.texture];
  if (t.type == TextureType::Constant) return t.value.x;
  ctx.warn("a non-constant texture for '" + name + "' is not supported; using " + std::to_string(fallback));
  return fallback;
}

void make_named_texture(const std::string& name, const std::string& kind, const std::string& texture_class,
                        const ParamSet& params, const glm::dmat4& render_from_texture, const DirectiveContext& ctx) {
  const bool spectrum = kind == "spectrum" || kind == "color";
  if (!spectrum && kind != "float") ctx.fail("texture kind must be \"float\" or \"spectrum\", got \"" + kind + "\"");
  // pbrt-v4 defines the noise textures for one kind only.
  const bool float_only = texture_class == "fbm" || texture_class == "wrinkled" || texture_class == "windy";
  if ((float_only && spectrum) || (texture_class == "marble" && !spectrum))
    ctx.fail("\"" + texture_class + "\" is not a " + kind + " texture in pbrt-v4 (it is a " +
             (float_only ? "float" : "spectrum") + " texture)");
  Texture t;
  if (texture_class == "constant") {
    t.type = TextureType::Constant;
    t.value = spectrum ? params.get_rgb("value").value_or(Rgb(1.f)) : Rgb(params.get_float("value", 1.f));
  } else if (texture_class == "imagemap") {
    t.type = TextureType::Image;
    std::string filename = params.get_string("filename", "");
    if (filename.empty()) ctx.fail("imagemap texture needs \"string filename\"");
    t.image = image_index(filename, params.get_string("encoding", "sRGB"), !spectrum, ctx);
    t.scale = params.get_float("scale", 1.f);
    t.invert = params.get_bool("invert", false);
    read_mapping_2d(t, params, render_from_texture, ctx);
    read_image_lookup(t, params, ctx);
  } else if (texture_class == "scale") {
    t.type = TextureType::Scale;
    t.a = any_slot(params, "tex", spectrum, Rgb(1.f), ctx);
    t.b = float_slot(params, "scale", 1.f, ctx);
  } else if (texture_class == "checkerboard") {
    t.type = TextureType::Checkerboard;
    const int dimension = params.get_int("dimension", 2);
    if (dimension != 2 && dimension != 3)
      ctx.fail(std::to_string(dimension) + " dimensional checkerboard texture not supported (2 or 3)");
    t.a = any_slot(params, "tex1", spectrum, Rgb(1.f), ctx);
    t.b = any_slot(params, "tex2", spectrum, Rgb(0.f), ctx);
    if (dimension == 3) set_mapping_3d(t, render_from_texture, ctx);
    else read_mapping_2d(t, params, render_from_texture, ctx);
  } else if (texture_class == "mix") {
    t.type = TextureType::Mix;
    t.a = any_slot(params, "tex1", spectrum, Rgb(0.f), ctx);
    t.b = any_slot(params, "tex2", spectrum, Rgb(1.f), ctx);
    t.amount = float_slot(params, "amount", 0.5f, ctx);
  } else if (texture_class == "directionmix") {
    t.type = TextureType::DirectionMix;
    t.a = any_slot(params, "tex1", spectrum, Rgb(0.f), ctx);
    t.b = any_slot(params, "tex2", spectrum, Rgb(1.f), ctx);
    const glm::dvec3 dir = glm::dmat3(render_from_texture) * glm::dvec3(params.get_point3("dir").value_or(Vec3(0.f, 1.f, 0.f)));
    const double len = glm::length(dir);
    if (!(len > 0.0) || !std::isfinite(len)) ctx.fail("directionmix \"dir\" must be a non-zero, finite direction");
    t.dir = Vec3(dir / len);
  } else if (texture_class == "bilerp") {
    t.type = TextureType::Bilerp;
    const char* names[4] = {"v00", "v01", "v10", "v11"};
    const Float defaults[4] = {0.f, 1.f, 0.f, 1.f};
    for (int i = 0; i < 4; ++i)
      t.corners[i] = spectrum ? params.get_rgb(names[i]).value_or(Rgb(defaults[i]))
                              : Rgb(params.get_float(names[i], defaults[i]));
    read_mapping_2d(t, params, render_from_texture, ctx);
  } else if (texture_class == "dots") {
    // pbrt-v4's DotsTexture constructor takes (outside, inside) but its
    // Create passes ("inside", "outside"): the dots show "outside" and the
    // rest "inside". We draw what pbrt-v4 draws.
    t.type = TextureType::Dots;
    t.a = any_slot(params, "outside", spectrum, Rgb(0.f), ctx);
    t.b = any_slot(params, "inside", spectrum, Rgb(1.f), ctx);
    read_mapping_2d(t, params, render_from_texture, ctx);
  } else if (texture_class == "fbm" || texture_class == "wrinkled") {
    t.type = texture_class == "fbm" ? TextureType::FBm : TextureType::Wrinkled;
    read_octaves(t, params, ctx);
    set_mapping_3d(t, render_from_texture, ctx);
  } else if (texture_class == "windy") {
    t.type = TextureType::Windy;
    set_mapping_3d(t, render_from_texture, ctx);
  } else if (texture_class == "marble") {
    t.type = TextureType::Marble;
    read_octaves(t, params, ctx);
    t.scale = params.get_float("scale", 1.f);
    t.variation = params.get_float("variation", 0.2f);
    set_mapping_3d(t, render_from_texture, ctx);
  } else {
    ctx.warn("unsupported texture class \"" + texture_class + "\"; using a constant 0.5");
    t.type = TextureType::Constant;
    t.value = Rgb(0.5f);
    params.mark_all_used();  // its parameters are unsupported, not unknown: one warning is enough
  }
  auto& table = spectrum ? ctx.names.spectrum_textures : ctx.names.float_textures;
  if (table.count(name)) ctx.warn(kind + " texture \"" + name + "\" redefined");
  table[name] = add_texture(ctx, t);
}

}  // namespace tessera
