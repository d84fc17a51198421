#include "scene/pbrt_textures.h"

#include <algorithm>
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

// "uv" mapping parameters shared by imagemap and checkerboard.
void read_uv_mapping(Texture& t, const ParamSet& params, const DirectiveContext& ctx) {
  std::string mapping = params.get_string("mapping", "uv");
  if (mapping != "uv") ctx.warn("texture mapping \"" + mapping + "\" is not supported; using \"uv\"");
  t.su = params.get_float("uscale", 1.f);
  t.sv = params.get_float("vscale", 1.f);
  t.du = params.get_float("udelta", 0.f);
  t.dv = params.get_float("vdelta", 0.f);
}

// A texture parameter that may be a value or a texture name, of either kind.
TextureSlot any_slot(const ParamSet& params, const std::string& name, bool spectrum, Rgb fallback,
                     const DirectiveContext& ctx) {
  return spectrum ? spectrum_slot(params, name, fallback, ctx) : float_slot(params, name, fallback.x, ctx);
}

}  // namespace

int32_t image_index(const std::string& filename, const std::string& encoding_name, bool grey,
                    const DirectiveContext& ctx) {
  std::string path = resolve_scene_path(filename, ctx.including_dir, ctx.search_dir);
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
                        const ParamSet& params, const DirectiveContext& ctx) {
  const bool spectrum = kind == "spectrum" || kind == "color";
  if (!spectrum && kind != "float") ctx.fail("texture kind must be \"float\" or \"spectrum\", got \"" + kind + "\"");
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
    read_uv_mapping(t, params, ctx);
    // Filtering and wrapping: we always bilinear-filter and repeat.
    params.get_string("filter", "bilinear");
    params.get_float("maxanisotropy", 8.f);
    std::string wrap = params.get_string("wrap", "repeat");
    if (wrap != "repeat") ctx.warn("texture wrap mode \"" + wrap + "\" is not supported; using \"repeat\"");
  } else if (texture_class == "scale") {
    t.type = TextureType::Scale;
    t.a = any_slot(params, "tex", spectrum, Rgb(1.f), ctx);
    t.b = float_slot(params, "scale", 1.f, ctx);
  } else if (texture_class == "checkerboard") {
    t.type = TextureType::Checkerboard;
    if (params.get_int("dimension", 2) != 2) ctx.warn("3D checkerboard textures are not supported; using 2D");
    t.a = any_slot(params, "tex1", spectrum, Rgb(1.f), ctx);
    t.b = any_slot(params, "tex2", spectrum, Rgb(0.f), ctx);
    read_uv_mapping(t, params, ctx);
  } else if (texture_class == "mix") {
    t.type = TextureType::Mix;
    t.a = any_slot(params, "tex1", spectrum, Rgb(0.f), ctx);
    t.b = any_slot(params, "tex2", spectrum, Rgb(1.f), ctx);
    t.amount = float_slot(params, "amount", 0.5f, ctx);
  } else if (texture_class == "bilerp") {
    t.type = TextureType::Bilerp;
    const char* names[4] = {"v00", "v01", "v10", "v11"};
    const Float defaults[4] = {0.f, 1.f, 0.f, 1.f};
    for (int i = 0; i < 4; ++i)
      t.corners[i] = spectrum ? params.get_rgb(names[i]).value_or(Rgb(defaults[i]))
                              : Rgb(params.get_float(names[i], defaults[i]));
    read_uv_mapping(t, params, ctx);
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
