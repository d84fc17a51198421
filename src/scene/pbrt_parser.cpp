#include "scene/pbrt_parser.h"

#include "scene/load_stop.h"
#include "scene/object_instances.h"

#include <cmath>
#include <filesystem>
#include <sstream>

#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/type_ptr.hpp>

#include "scene/light_paths.h"
#include "scene/pbrt_film.h"
#include "scene/pbrt_lights.h"
#include "scene/pbrt_materials.h"
#include "scene/pbrt_media.h"
#include "scene/pbrt_paths.h"
#include "scene/scene_file.h"
#include "scene/pbrt_shapes.h"
#include "scene/pbrt_textures.h"
#include "scene/sampler_setup.h"
#include "scene/scene_limits.h"
#include "scene/named_spectra.h"
#include "scene/spectrum_file.h"

namespace tessera {
namespace {

constexpr int kMaxIncludeDepth = 32;

[[noreturn]] void fail(const Token& at, const std::string& problem) { throw SceneError(at.where() + ": " + problem); }

// The Integrator's "lightsampler" (pbrt-v4: bvh, power, uniform, exhaustive).
LightSamplerKind light_sampler_of(const ParamSet& ps, const Token& at, std::vector<std::string>& warnings) {
  const std::string name = ps.get_string("lightsampler", "bvh");
  for (LightSamplerKind k : {LightSamplerKind::Bvh, LightSamplerKind::Power, LightSamplerKind::Uniform})
    if (name == light_sampler_name(k)) return k;
  if (name == "exhaustive") {
    warnings.push_back(at.where() + ": light sampler \"exhaustive\" is drawn as \"bvh\" (the same image in expectation)");
    return LightSamplerKind::Bvh;
  }
  fail(at, "unknown light sampler \"" + name + "\" (bvh, power, uniform or exhaustive)");
}

const Token& next_token(TokenStream& tokens, size_t& pos, const Token& at, const char* what) {
  if (!tokens.has(pos)) fail(at, std::string("missing ") + what + " after " + at.text);
  return tokens[pos++];
}

std::string read_string(TokenStream& tokens, size_t& pos, const Token& at) {
  const Token& t = next_token(tokens, pos, at, "a quoted string");
  if (t.kind != TokenKind::String) fail(t, "expected a quoted string after " + at.text + ", got '" + t.text + "'");
  return t.text;
}

// `count` numbers, optionally bracketed (Transform [ ... ] and Transform ... are both seen).
// In double, as the transforms they build are composed (GraphicsState).
std::vector<double> read_numbers(TokenStream& tokens, size_t& pos, size_t count, const Token& at) {
  bool bracketed = tokens.has(pos) && tokens[pos].kind == TokenKind::OpenBracket;
  if (bracketed) ++pos;
  std::vector<double> out;
  while (out.size() < count) {
    if (!tokens.has(pos) || (tokens[pos].kind == TokenKind::Word && is_pbrt_directive_name(tokens[pos].text)) ||
        tokens[pos].kind == TokenKind::CloseBracket)
      fail(at, at.text + " needs " + std::to_string(count) + " numbers, got " + std::to_string(out.size()));
    const Token& t = tokens[pos++];
    if (t.kind != TokenKind::Number) fail(t, "malformed number '" + t.text + "' for " + at.text);
    out.push_back(t.number);
  }
  if (bracketed) {
    if (!tokens.has(pos) || tokens[pos].kind != TokenKind::CloseBracket)
      fail(at, "unterminated array for " + at.text + " (expected " + std::to_string(count) + " numbers and ']')");
    ++pos;
  }
  return out;
}

// Skips an unsupported directive's arguments: everything up to the next word
// outside brackets that is not a bare bool.
void skip_arguments(TokenStream& tokens, size_t& pos) {
  int depth = 0;
  while (tokens.has(pos)) {
    const Token& t = tokens[pos];
    if (t.kind == TokenKind::OpenBracket) ++depth;
    else if (t.kind == TokenKind::CloseBracket) depth = depth > 0 ? depth - 1 : 0;
    else if (t.kind == TokenKind::Word && depth == 0 && t.text != "true" && t.text != "false") return;
    ++pos;
  }
}

// A spectrum named by a string that is not one of pbrt's named spectra is a
// file of wavelength/value pairs (pbrt-v4: relative to the scene's
// directory); it is read here, so the parameter holds its pairs from now on.
void read_spectrum_files(std::vector<Param>& params, const std::string& including_dir, const std::string& search_dir,
                         std::vector<std::string>* files_read) {
  for (Param& p : params) {
    if (p.type != "spectrum" || p.strings.size() != 1 || named_spectrum_rgb(p.strings[0])) continue;
    const std::string path = resolve_scene_path(p.strings[0], including_dir, search_dir);
    files_read->push_back(path);
    std::error_code ec;
    if (!std::filesystem::is_regular_file(path, ec))
      throw SceneError(p.where + ": unknown named spectrum \"" + p.strings[0] + "\" (and no spectrum file '" + path +
                       "')");
    try {
      const std::vector<Float> pairs = read_spectrum_file(path);
      p.numbers.assign(pairs.begin(), pairs.end());
    } catch (const SceneError& e) {
      throw SceneError(p.where + ": " + e.what());
    }
    p.file = p.strings[0];
    p.strings.clear();
  }
}

ParamSet read_params(TokenStream& tokens, size_t& pos, std::string owner, std::vector<std::string>& warnings,
                     const std::string& including_dir, const std::string& search_dir,
                     std::vector<std::string>* files_read) {
  std::vector<Param> params = parse_param_list(tokens, pos);
  read_spectrum_files(params, including_dir, search_dir, files_read);
  ParamSet ps(std::move(params), std::move(owner));
  ps.warnings = &warnings;
  return ps;
}

// pbrt-v4 LookAt: the camera-from-world transform of a camera at `eye` (in double, see GraphicsState).
glm::dmat4 look_at(glm::dvec3 eye, glm::dvec3 target, glm::dvec3 up, const Token& at, std::vector<std::string>& warnings) {
  glm::dvec3 dir = target - eye;
  if (glm::length(dir) == 0.0) fail(at, "LookAt eye and target coincide");
  dir = glm::normalize(dir);
  glm::dvec3 right = glm::cross(glm::normalize(up), dir);
  if (!(glm::length(right) > 0.0)) {
    warnings.push_back(at.where() + ": LookAt up vector is parallel to the view direction; ignored");
    return glm::dmat4(1.0);
  }
  right = glm::normalize(right);
  glm::dvec3 new_up = glm::cross(dir, right);
  glm::dmat4 world_from_camera(glm::dvec4(right, 0.0), glm::dvec4(new_up, 0.0), glm::dvec4(dir, 0.0), glm::dvec4(eye, 1.0));
  return glm::inverse(world_from_camera);
}

bool is_world_directive(const std::string& d) {
  return d == "Shape" || d == "Material" || d == "MakeNamedMaterial" || d == "NamedMaterial" || d == "Texture" ||
         d == "LightSource" || d == "AreaLightSource" || d == "ObjectBegin" || d == "ObjectEnd" ||
         d == "ObjectInstance" || d == "ReverseOrientation";
}

bool is_options_directive(const std::string& d) {
  return d == "Camera" || d == "Film" || d == "Sampler" || d == "Integrator" || d == "PixelFilter" ||
         d == "Accelerator";
}

std::string quoted(const std::string& directive, const std::string& type) { return directive + " \"" + type + "\""; }

}  // namespace

PbrtParser::PbrtParser(std::string search_dir) : search_dir_(std::move(search_dir)) {
  scene_.materials.push_back(Material{});  // pbrt's default: diffuse 0.5
}

DirectiveContext PbrtParser::context(const Token& at, const std::string& including_dir) {
  return DirectiveContext{scene_, names_, at.where(), including_dir, search_dir_};
}

int PbrtParser::parse_stream(std::istream& in, const std::string& file_name, const std::string& including_dir) {
  TokenStream tokens(in, file_name);
  parse_tokens(tokens, including_dir);
  return tokens.last_line();
}

void PbrtParser::parse_tokens(TokenStream& tokens, const std::string& including_dir) {
  size_t pos = 0;
  while (tokens.has(pos)) {
    check_load_stop();
    directive(tokens, pos, including_dir);
  }
}

void PbrtParser::require_world(const Token& at, bool inside) const {
  if (inside && !world_begun_) fail(at, "'" + at.text + "' before WorldBegin (missing WorldBegin?)");
  if (!inside && world_begun_) fail(at, "'" + at.text + "' is not allowed after WorldBegin");
}

void PbrtParser::push(char kind, const Token& at) { stack_.push_back({kind, state_, at.where()}); }

void PbrtParser::pop(char kind, const Token& at) {
  if (stack_.empty()) {
    const char* begin = kind == 'o' ? "ObjectBegin" : kind == 't' ? "TransformBegin" : "AttributeBegin";
    fail(at, at.text + " without matching " + begin);
  }
  StackEntry e = stack_.back();
  stack_.pop_back();
  if (e.kind != kind)
    scene_.warnings.push_back(at.where() + ": " + at.text + " closes the block opened at " + e.where);
  if (kind == 't') {  // TransformEnd restores only the transforms
    state_.ctm = e.state.ctm;
    state_.ctm_end = e.state.ctm_end;
    state_.active_start = e.state.active_start;
    state_.active_end = e.state.active_end;
  } else {
    state_ = e.state;
  }
}

void PbrtParser::directive(TokenStream& tokens, size_t& pos, const std::string& including_dir) {
  // Everything before this directive is done with: drop it (a copy of `at` is kept).
  tokens.release_before(pos);
  const Token at = tokens[pos++];
  if (at.kind != TokenKind::Word) fail(at, "expected a directive, got '" + at.text + "'");
  const std::string& d = at.text;
  if (is_world_directive(d)) require_world(at, true);
  if (is_options_directive(d)) require_world(at, false);
  std::vector<std::string>& warnings = scene_.warnings;
  auto warn = [&](const std::string& m) { warnings.push_back(at.where() + ": " + m); };
  const Mat4 ctm(state_.ctm);  // rounded to float where it places things
  // Transform directives change the active transforms (ActiveTransform): the
  // start one, the end one, or both.
  auto set_active = [&](const DMat4& start, const DMat4& end) {
    if (state_.active_start) state_.ctm = start;
    if (state_.active_end) state_.ctm_end = end;
  };
  auto post_multiply = [&](const DMat4& m) { set_active(state_.ctm * m, state_.ctm_end * m); };

  if (d == "Translate") {
    std::vector<double> v = read_numbers(tokens, pos, 3, at);
    post_multiply(glm::translate(DMat4(1.0), glm::dvec3(v[0], v[1], v[2])));
  } else if (d == "Scale") {
    std::vector<double> v = read_numbers(tokens, pos, 3, at);
    post_multiply(glm::scale(DMat4(1.0), glm::dvec3(v[0], v[1], v[2])));
  } else if (d == "Rotate") {
    std::vector<double> v = read_numbers(tokens, pos, 4, at);
    const glm::dvec3 axis(v[1], v[2], v[3]);
    if (glm::length(axis) == 0.0) fail(at, "Rotate axis is zero");
    post_multiply(glm::rotate(DMat4(1.0), v[0] * 3.14159265358979323846 / 180.0, glm::normalize(axis)));
  } else if (d == "LookAt") {
    std::vector<double> v = read_numbers(tokens, pos, 9, at);
    post_multiply(look_at(glm::dvec3(v[0], v[1], v[2]), glm::dvec3(v[3], v[4], v[5]), glm::dvec3(v[6], v[7], v[8]), at,
                          warnings));
  } else if (d == "Transform" || d == "ConcatTransform") {
    // pbrt-v4 reads the 16 numbers row-major and transposes: they are the
    // matrix's columns, exactly glm's storage order.
    std::vector<double> v = read_numbers(tokens, pos, 16, at);
    // The last row makes w: all zero, every point maps to infinity (pbrt-v4
    // divides by w), which would put the shapes anywhere, the camera too.
    if (v[3] == 0.0 && v[7] == 0.0 && v[11] == 0.0 && v[15] == 0.0)
      fail(at, d + ": the matrix's last row (its 4th, 8th, 12th and 16th numbers) is zero: every point would map to infinity");
    const DMat4 m = glm::make_mat4(v.data());
    if (d == "ConcatTransform") post_multiply(m);
    else if (world_begun_) set_active(render_from_world_ * m, render_from_world_ * m);  // m is world-space
    else set_active(m, m);
  } else if (d == "Identity") {
    const DMat4 identity = world_begun_ ? render_from_world_ : DMat4(1.0);
    set_active(identity, identity);
  } else if (d == "CoordinateSystem") {
    coordinate_systems_[read_string(tokens, pos, at)] = {state_.ctm, state_.ctm_end, world_begun_};
  } else if (d == "CoordSysTransform") {
    std::string name = read_string(tokens, pos, at);
    auto it = coordinate_systems_.find(name);
    if (it == coordinate_systems_.end()) {
      warn("unknown coordinate system \"" + name + "\"; ignored");
    } else {
      // The CTM is world-space before WorldBegin and render-space after it.
      DMat4 start = it->second.start, end = it->second.end;
      if (world_begun_ && !it->second.render_space) {
        start = render_from_world_ * start;
        end = render_from_world_ * end;
      } else if (!world_begun_ && it->second.render_space) {
        start = world_from_render_ * start;
        end = world_from_render_ * end;
      }
      state_.ctm = start;
      state_.ctm_end = end;
    }
  } else if (d == "ReverseOrientation") {
    state_.reverse_orientation = !state_.reverse_orientation;
  } else if (d == "AttributeBegin") {
    push('a', at);
  } else if (d == "AttributeEnd") {
    pop('a', at);
  } else if (d == "TransformBegin" || d == "TransformEnd") {
    warn(d + " is deprecated in pbrt-v4; treated as a transform-only block");
    if (d == "TransformBegin") push('t', at);
    else pop('t', at);
  } else if (d == "Include" || d == "Import") {
    std::string name = read_string(tokens, pos, at);
    std::string path = resolve_scene_path(name, including_dir, search_dir_);
    scene_.files_read.push_back(path);
    std::unique_ptr<std::istream> in = open_scene_file(path);
    if (!in || !*in) fail(at, d + " file '" + path + "' not found or unreadable");
    if (include_depth_ >= kMaxIncludeDepth) fail(at, d + " nested too deeply (recursive include?)");
    ++include_depth_;
    parse_stream(*in, path, directory_of(path));
    --include_depth_;
  } else if (d == "WorldBegin") {
    if (world_begun_) fail(at, "WorldBegin appears twice");
    world_begun_ = true;
    state_.ctm = state_.ctm_end = render_from_world_;
    state_.active_start = state_.active_end = true;
    coordinate_systems_["world"] = {state_.ctm, state_.ctm_end, true};
  } else if (d == "WorldEnd") {
    warn("WorldEnd is pbrt-v3 syntax; ignored");
  } else if (d == "Camera") {
    std::string type = read_string(tokens, pos, at);
    camera(at, type, read_params(tokens, pos, quoted(d, type), warnings, including_dir, search_dir_, &scene_.files_read));
  } else if (d == "Film") {
    std::string type = read_string(tokens, pos, at);
    ParamSet ps = read_params(tokens, pos, quoted(d, type), warnings, including_dir, search_dir_, &scene_.files_read);
    read_film(type, ps, at.where(), scene_.film, warnings);
    ps.report_unused(warnings);
  } else if (d == "Sampler") {
    std::string type = read_string(tokens, pos, at);
    ParamSet ps = read_params(tokens, pos, quoted(d, type), warnings, including_dir, search_dir_, &scene_.files_read);
    scene_.spp = ps.get_int("pixelsamples", 16);
    if (scene_.spp <= 0) fail(at, "pixelsamples must be positive");
    scene_.seed = static_cast<uint64_t>(ps.get_int("seed", static_cast<int>(scene_.seed)));
    if (const std::optional<SamplerKind> kind = sampler_kind_named(type)) {
      scene_.sampler = *kind;
      if (type == "sobol")
        warn("sampler \"sobol\": drawn as \"paddedsobol\" (Owen-scrambled Sobol points per pixel); the same image "
             "in expectation, not pbrt-v4's global Sobol ordering of the pixels");
    } else {
      scene_.sampler = SamplerKind::ZSobol;
      if (type == "pmj02bn")
        warn("sampler \"" + type + "\": drawn as \"zsobol\"; the same image in expectation, not pbrt-v4's own point set");
      else
        warn("sampler \"" + type + "\" is unknown; using \"zsobol\"");
    }
    if (type == "stratified") {
      // pbrt-v4: xsamples x ysamples jittered strata; pixelsamples is not read.
      scene_.strata_x = ps.get_int("xsamples", 4);
      scene_.strata_y = ps.get_int("ysamples", 4);
      if (scene_.strata_x <= 0 || scene_.strata_y <= 0 ||
          static_cast<int64_t>(scene_.strata_x) * scene_.strata_y > 1073741824)
        fail(at, "xsamples and ysamples must be positive, their product at most 2^30");
      scene_.spp = scene_.strata_x * scene_.strata_y;
      scene_.sampler_jitter = ps.get_bool("jitter", true);
    }
    scene_.sampler_spp = scene_.spp;
    ps.find_any("jitter");
    if (type == "halton") {
      // pbrt-v4: permutedigits (default), none, owen.
      const std::string r = ps.get_string("randomization", "permutedigits");
      if (r == "permutedigits") scene_.halton_randomize = HaltonRandomize::PermuteDigits;
      else if (r == "none") scene_.halton_randomize = HaltonRandomize::None;
      else if (r == "owen") scene_.halton_randomize = HaltonRandomize::Owen;
      else fail(at, "unknown halton randomization \"" + r + "\" (permutedigits, none or owen)");
    }
    ps.find_any("randomization");
    ps.report_unused(warnings);
  } else if (d == "Integrator") {
    std::string type = read_string(tokens, pos, at);
    ParamSet ps = read_params(tokens, pos, quoted(d, type), warnings, including_dir, search_dir_, &scene_.files_read);
    scene_.integrator = type;
    if (bidirectional_integrator(type))
      warn("integrator \"" + type + "\" is rendered as \"volpath\" plus caustics traced from the lights (--light-paths)");
    else if (type != "path" && type != "volpath")
      warn("integrator \"" + type + "\" is rendered with \"path\"");
    scene_.max_depth = ps.get_int("maxdepth", 5);
    if (scene_.max_depth < 0) fail(at, "maxdepth must not be negative");
    scene_.light_sampler = light_sampler_of(ps, at, warnings);
    if (type != "path") ps.mark_all_used();
    ps.report_unused(warnings);
  } else if (d == "PixelFilter") {
    std::string type = read_string(tokens, pos, at);
    ParamSet ps = read_params(tokens, pos, quoted(d, type), warnings, including_dir, search_dir_, &scene_.files_read);
    scene_.filter = read_filter(type, ps, at.where(), warnings);
    ps.report_unused(warnings);
  } else if (d == "Material") {
    std::string type = read_string(tokens, pos, at);
    ParamSet ps = read_params(tokens, pos, quoted(d, type), warnings, including_dir, search_dir_, &scene_.files_read);
    scene_.materials.push_back(make_material(type, ps, context(at, including_dir)));
    state_.material = static_cast<int32_t>(scene_.materials.size() - 1);
    ps.report_unused(warnings);
  } else if (d == "MakeNamedMaterial") {
    std::string name = read_string(tokens, pos, at);
    ParamSet ps = read_params(tokens, pos, quoted(d, name), warnings, including_dir, search_dir_, &scene_.files_read);
    std::string type = ps.get_string("type", "");
    if (type.empty()) fail(at, "MakeNamedMaterial \"" + name + "\" needs \"string type\"");
    if (names_.materials.count(name)) warn("named material \"" + name + "\" redefined");
    scene_.materials.push_back(make_material(type, ps, context(at, including_dir)));
    names_.materials[name] = static_cast<int32_t>(scene_.materials.size() - 1);
    ps.report_unused(warnings);
  } else if (d == "NamedMaterial") {
    std::string name = read_string(tokens, pos, at);
    auto it = names_.materials.find(name);
    if (it == names_.materials.end()) fail(at, "unknown named material \"" + name + "\"");
    state_.material = it->second;
  } else if (d == "Texture") {
    std::string name = read_string(tokens, pos, at);
    std::string kind = read_string(tokens, pos, at);
    std::string cls = read_string(tokens, pos, at);
    ParamSet ps = read_params(tokens, pos, quoted(d, name), warnings, including_dir, search_dir_, &scene_.files_read);
    // Before WorldBegin the CTM is world-space: the texture's space goes to render space too.
    const DMat4 render_from_texture = world_begun_ ? state_.ctm : render_from_world_ * state_.ctm;
    make_named_texture(name, kind, cls, ps, render_from_texture, context(at, including_dir));
    ps.report_unused(warnings);
  } else if (d == "LightSource") {
    std::string type = read_string(tokens, pos, at);
    ParamSet ps = read_params(tokens, pos, quoted(d, type), warnings, including_dir, search_dir_, &scene_.files_read);
    if (state_.ctm_end != state_.ctm) warn("a moving light stays where it starts (pbrt-v4 uses its start transform too)");
    if (auto light = make_light(type, ps, ctm, Mat4(render_from_world_), context(at, including_dir))) {
      if (!open_instance_.empty()) warn("lights inside ObjectBegin are not instanced; added once");
      light->medium = state_.media.outside;  // resolved with the other medium names in resolve_media()
      scene_.lights.push_back(*light);
    }
    ps.report_unused(warnings);
  } else if (d == "AreaLightSource") {
    std::string type = read_string(tokens, pos, at);
    ParamSet ps = read_params(tokens, pos, quoted(d, type), warnings, including_dir, search_dir_, &scene_.files_read);
    scene_.area_lights.push_back(make_area_light(type, ps, context(at, including_dir)));
    state_.area_light = static_cast<int32_t>(scene_.area_lights.size() - 1);
    ps.report_unused(warnings);
  } else if (d == "Shape") {
    std::string type = read_string(tokens, pos, at);
    ParamSet ps = read_params(tokens, pos, quoted(d, type), warnings, including_dir, search_dir_, &scene_.files_read);
    shape(at, type, ps, including_dir);
    ps.report_unused(warnings);
  } else if (d == "ObjectBegin") {
    std::string name = read_string(tokens, pos, at);
    if (!open_instance_.empty()) fail(at, "ObjectBegin \"" + name + "\" inside ObjectBegin \"" + open_instance_ + "\"");
    if (objects_.count(name)) warn("object \"" + name + "\" redefined");
    push('o', at);
    open_instance_ = name;
    // A redefinition is a new object: instances made before it keep the old one.
    objects_[name] = static_cast<uint32_t>(scene_.objects.size());
    scene_.objects.push_back(ObjectDesc{name, {}});
  } else if (d == "ObjectEnd") {
    if (open_instance_.empty()) fail(at, "ObjectEnd without matching ObjectBegin");
    pop('o', at);
    open_instance_.clear();
  } else if (d == "ObjectInstance") {
    std::string name = read_string(tokens, pos, at);
    if (!open_instance_.empty()) fail(at, "ObjectInstance inside ObjectBegin \"" + open_instance_ + "\"");
    auto it = objects_.find(name);
    if (it == objects_.end()) fail(at, "unknown object \"" + name + "\"");
    object_instance(at, it->second);
  } else if (d == "ActiveTransform") {
    const Token& which = next_token(tokens, pos, at, "All, StartTime or EndTime");
    if (which.text == "All") state_.active_start = state_.active_end = true;
    else if (which.text == "StartTime") state_.active_start = true, state_.active_end = false;
    else if (which.text == "EndTime") state_.active_start = false, state_.active_end = true;
    else fail(which, "ActiveTransform takes All, StartTime or EndTime, not '" + which.text + "'");
  } else if (d == "TransformTimes") {
    require_world(at, false);
    std::vector<double> v = read_numbers(tokens, pos, 2, at);
    if (!(v[1] > v[0]) || !std::isfinite(v[0]) || !std::isfinite(v[1]))
      fail(at, "TransformTimes needs a start time below its end time");
    scene_.camera.transform_start_time = static_cast<Float>(v[0]);
    scene_.camera.transform_end_time = static_cast<Float>(v[1]);
  } else if (d == "MakeNamedMedium") {
    std::string name = read_string(tokens, pos, at);
    ParamSet ps = read_params(tokens, pos, quoted(d, name), warnings, including_dir, search_dir_, &scene_.files_read);
    std::string type = ps.get_string("type", "");
    if (type.empty()) fail(at, "MakeNamedMedium \"" + name + "\" needs \"string type\"");
    if (names_.media.count(name)) warn("named medium \"" + name + "\" redefined");
    if (state_.ctm_end != state_.ctm) warn("a moving medium stays where it starts (pbrt-v4 uses its start transform too)");
    // Before WorldBegin the CTM is world-space: place the medium in render space too.
    const Mat4 render_from_medium(world_begun_ ? state_.ctm : render_from_world_ * state_.ctm);
    const Medium m = make_medium(type, ps, render_from_medium, context(at, including_dir));
    if (scene_.media.size() >= static_cast<size_t>(INT16_MAX)) fail(at, "too many media (at most 32767)");
    scene_.media.push_back(m);
    names_.media[name] = static_cast<int32_t>(scene_.media.size() - 1);
    ps.report_unused(warnings);
  } else if (d == "MediumInterface") {
    // One name: the same medium on both sides; two: inside, then outside.
    const std::string inside = read_string(tokens, pos, at);
    std::string outside = inside;
    if (tokens.has(pos) && tokens[pos].kind == TokenKind::String) outside = tokens[pos++].text;
    // pbrt-v4 looks media up by name when the scene is complete, so a medium
    // may be defined after its use: names are numbered here (as -2 - k) and
    // resolved in finish().
    auto medium_ref = [&](const std::string& name) -> int16_t {
      if (name.empty()) return -1;
      auto it = medium_refs_.find(name);
      if (it == medium_refs_.end()) {
        if (medium_refs_.size() >= 32000) fail(at, "too many medium names");
        it = medium_refs_.emplace(name, MediumRef{static_cast<int16_t>(-2 - static_cast<int>(medium_refs_.size())),
                                                  at.where()}).first;
      }
      return it->second.code;
    };
    state_.media.inside = medium_ref(inside);
    state_.media.outside = medium_ref(outside);
  } else if (d == "ColorSpace" || d == "Option" || d == "Attribute" || d == "Accelerator") {
    warn("'" + d + "' is not supported; ignored");
    skip_arguments(tokens, pos);
  } else {
    warn("unknown directive '" + d + "'; skipped");
    skip_arguments(tokens, pos);
  }
}

// The corners of the object's box, placed: within range, then so is every
// vertex (the cheap test, once per instance, for scenes of many instances).
// The box is the object's, computed at its first instance (the object is
// closed by then) and kept: a scene of many instances reads each vertex once.
bool PbrtParser::placed_within_range(uint32_t object, const InstanceDesc& inst) {
  if (object_boxes_.size() <= object) object_boxes_.resize(object + 1);
  ObjectBox& box = object_boxes_[object];
  if (!box.known) {
    for (const MeshDesc& m : scene_.objects[object].meshes)
      for (const std::vector<Vec3>* points : {&m.p, &m.p_end})
        for (const Vec3& p : *points) box.lo = glm::min(box.lo, p), box.hi = glm::max(box.hi, p);
    box.known = true;
  }
  const Vec3 &lo = box.lo, &hi = box.hi;
  if (!(lo.x <= hi.x)) return true;
  for (const Mat4* map : {&inst.render_from_object, &inst.render_from_object_end})
    for (int c = 0; c < 8; ++c) {
      const Vec3 corner(c & 1 ? hi.x : lo.x, c & 2 ? hi.y : lo.y, c & 4 ? hi.z : lo.z);
      if (!representable(Vec3(*map * Vec4(corner, 1.f)))) return false;
    }
  return true;
}

void PbrtParser::check_coordinates(const MeshDesc& mesh, const Token& at) const {
  for (const std::vector<Vec3>* points : {&mesh.p, &mesh.p_end})
    for (const Vec3& p : *points)
      if (!representable(p)) fail(at, "a vertex of the shape is " + describe_far(p, scene_.render_origin));
}

// Definitions are stored in render space; the instance's transform is
// world-space, so it acts between world_from_render and render_from_world
// (pbrt-v4: RenderFromObject() * worldFromRender).
void PbrtParser::object_instance(const Token& at, uint32_t object) {
  InstanceDesc inst;
  inst.object = object;
  inst.render_from_object = Mat4(state_.ctm * world_from_render_);
  inst.render_from_object_end = state_.ctm_end != state_.ctm ? Mat4(state_.ctm_end * world_from_render_)
                                                             : inst.render_from_object;
  inst.where = at.where();
  inst.meshes_before = scene_.meshes.size();
  const ObjectDesc& def = scene_.objects[object];
  // A singular map flattens the object (into a plane, a line or a point):
  // placed as ordinary meshes, as drawn without instancing.
  const bool singular = glm::determinant(Mat3(inst.render_from_object)) == 0.f ||
                        glm::determinant(Mat3(inst.render_from_object_end)) == 0.f;
  if (singular || !placed_within_range(object, inst)) {
    for (MeshDesc& m : placed_meshes(def, inst)) {
      check_coordinates(m, at);
      scene_.meshes.push_back(std::move(m));
    }
    return;
  }
  scene_.instances.push_back(std::move(inst));
}

void PbrtParser::camera(const Token& at, const std::string& type, const ParamSet& params) {
  std::vector<std::string>& warnings = scene_.warnings;
  CameraProjection projection = CameraProjection::Perspective;
  if (type == "orthographic") {
    projection = CameraProjection::Orthographic;
  } else if (type == "spherical") {
    const std::string mapping = params.get_string("mapping", "equalarea");
    if (mapping == "equalarea")
      projection = CameraProjection::SphericalEqualArea;
    else if (mapping == "equirectangular")
      projection = CameraProjection::SphericalEquirectangular;
    else
      fail(at, "spherical camera \"mapping\" \"" + mapping + "\" is unknown (equalarea, equirectangular)");
  } else if (type != "perspective") {
    warnings.push_back(at.where() + ": camera \"" + type + "\" treated as \"perspective\"");
  }
  scene_.camera.projection = projection;
  // pbrt-v4's CameraBase parameters.
  if (const std::vector<Float> w = params.get_floats("screenwindow"); !w.empty()) {
    // pbrt-v4 takes a reversed window too (a mirrored image); an empty one has no pixels.
    if (w.size() != 4 || !(w[1] != w[0]) || !(w[3] != w[2]) || !std::isfinite(w[0]) || !std::isfinite(w[1]) ||
        !std::isfinite(w[2]) || !std::isfinite(w[3]))
      fail(at, "camera \"screenwindow\" needs four finite values x0 x1 y0 y1 with x0 != x1, y0 != y1");
    scene_.camera.has_screen_window = true;
    scene_.camera.screen_window = Vec4(w[0], w[1], w[2], w[3]);
  }
  if (params.find_any("frameaspectratio")) {
    scene_.camera.frame_aspect_ratio = params.get_float("frameaspectratio", 0.f);
    if (!(scene_.camera.frame_aspect_ratio > 0.f) || !std::isfinite(scene_.camera.frame_aspect_ratio))
      fail(at, "camera \"frameaspectratio\" must be positive");
  }
  if (glm::determinant(state_.ctm) == 0.0) fail(at, "camera transform is singular");
  const DMat4 world_from_camera = glm::inverse(state_.ctm);
  const glm::dvec3 eye(world_from_camera[3]);
  if (!representable(Vec3(eye))) fail(at, "the camera is " + describe_far(Vec3(eye)));
  DMat4 world_from_camera_end = world_from_camera;
  if (state_.ctm_end != state_.ctm) {
    if (glm::determinant(state_.ctm_end) == 0.0) fail(at, "camera end transform is singular");
    world_from_camera_end = glm::inverse(state_.ctm_end);
  }
  // Render space: the world translated so that the camera (at its start
  // time) is at the origin.
  render_from_world_ = glm::translate(DMat4(1.0), -eye);
  world_from_render_ = glm::translate(DMat4(1.0), eye);
  scene_.render_origin = eye;
  scene_.camera.world_from_camera = Mat4(render_from_world_ * world_from_camera);
  scene_.camera.world_from_camera_end = Mat4(render_from_world_ * world_from_camera_end);
  if (projection == CameraProjection::Perspective) scene_.camera.fov_degrees = params.get_float("fov", 90.f);
  // pbrt-v4 swaps reversed shutter times and refuses a shutter that never opens.
  Float open = params.get_float("shutteropen", 0.f), close = params.get_float("shutterclose", 1.f);
  if (close < open) {
    warnings.push_back(at.where() + ": shutterclose is before shutteropen; swapped");
    std::swap(open, close);
  }
  if (!(close > open) || !std::isfinite(close - open))
    fail(at, "the shutter never opens (shutterclose equals shutteropen): the image would be black");
  scene_.camera.exposure_time = close - open;
  scene_.camera.shutter_open = open;
  scene_.camera.shutter_close = close;
  scene_.camera.where = at.where();
  scene_.camera_medium = state_.media.outside;  // pbrt-v4: the camera sits in the current outside medium
  coordinate_systems_["camera"] = {render_from_world_ * world_from_camera, render_from_world_ * world_from_camera_end, true};
  // The spherical camera has no lens (pbrt-v4 does not read one).
  const bool lens = projection == CameraProjection::Perspective || projection == CameraProjection::Orthographic;
  scene_.camera.lens_radius = lens ? params.get_float("lensradius", 0.f) : 0.f;
  scene_.camera.focal_distance = lens ? params.get_float("focaldistance", 1e6f) : 1e6f;
  if (!(scene_.camera.lens_radius >= 0.f) || !std::isfinite(scene_.camera.lens_radius))
    fail(at, "camera \"lensradius\" must not be negative");
  if (!(scene_.camera.focal_distance > 0.f) || !std::isfinite(scene_.camera.focal_distance))
    fail(at, "camera \"focaldistance\" must be positive and finite");
  if (type != "perspective" && type != "orthographic" && type != "spherical") params.mark_all_used();
  params.report_unused(warnings);
}

void PbrtParser::shape(const Token& at, const std::string& type, const ParamSet& params,
                       const std::string& including_dir) {
  ShapeContext ctx{at.where(), including_dir,     search_dir_,         Mat4(state_.ctm),
                   state_.reverse_orientation, &scene_.warnings, &scene_.files_read, {}};
  ctx.float_texture = [this, &at](const std::string& name) -> DisplacementFn {
    auto it = names_.float_textures.find(name);
    if (it == names_.float_textures.end()) fail(at, "unknown float texture \"" + name + "\" for \"displacement\"");
    auto textures = std::make_shared<HostTextures>(scene_);
    const TextureSlot slot{it->second, Rgb(0.f)};
    // pbrt-v4 sets only p and uv of the context it displaces with: the normal is 0.
    return [textures, slot](const Vec3& p, Vec2 uv) { return textures->eval(slot, p, Vec3(0.f), uv); };
  };
  std::optional<MeshDesc> mesh = make_shape_mesh(type, params, ctx);
  if (!mesh) {
    params.mark_all_used();
    return;
  }
  mesh->material = state_.material;
  mesh->area_light = state_.area_light;
  if (mesh->area_light >= 0 && scene_.materials[state_.material].type == MaterialType::Interface) {
    // pbrt-v4 (CreateLights) ignores them too: such shapes only bound media.
    scene_.warnings.push_back(at.where() + ": an area light on a shape with the \"interface\" material is ignored");
    mesh->area_light = -1;
  }
  if (mesh->area_light >= 0 && mesh->mixed_faces && scene_.area_lights[mesh->area_light].power > 0.f)
    scene_.warnings.push_back(at.where() + ": area light \"power\" on a PLY of triangles and quads goes to each "
                              "triangle; pbrt-v4 gives it to each quad whole (each quad here emits twice that)");
  mesh->media = state_.media;
  // A subsurface material's medium fills its shapes (inside: the side the
  // geometric normal points away from).
  if (scene_.materials[state_.material].type == MaterialType::Subsurface)
    mesh->media.inside = static_cast<int16_t>(scene_.materials[state_.material].subsurface_medium);
  if (state_.ctm_end != state_.ctm) {
    if (mesh->area_light >= 0) {
      scene_.warnings.push_back(at.where() + ": a moving area light is not supported; it stays where it starts");
    } else if (glm::determinant(state_.ctm) == 0.0) {
      scene_.warnings.push_back(at.where() + ": the shape's start transform is singular; it does not move");
    } else {
      const Mat4 end_from_start(state_.ctm_end * glm::inverse(state_.ctm));
      add_motion(*mesh, end_from_start);
      // Vertices move on straight lines: exact for translation and scale, a
      // chord instead of pbrt-v4's arc for a rotation.
      const Mat3 l(end_from_start);
      Float off = 0.f, diag = 0.f;
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) (i == j ? diag : off) += std::abs(l[i][j]);
      if (off > 0.05f * diag)
        scene_.warnings.push_back(at.where() + ": a rotating shape's vertices move on straight lines (pbrt-v4 "
                                  "interpolates the rotation): fast spins are blurred differently");
    }
  }
  mesh->alpha = float_slot(params, "alpha", 1.f, context(at, including_dir));
  if (mesh->alpha.texture < 0 && !(mesh->alpha.value.x >= 0.f && mesh->alpha.value.x <= 1.f))
    fail(at, "shape \"alpha\" must be in [0, 1]");
  if ((mesh->alpha.texture >= 0 || mesh->alpha.value.x < 1.f) && mesh->area_light >= 0)
    scene_.warnings.push_back(at.where() + ": \"alpha\" on an emissive shape cuts out its surface but not its emission");
  if (!open_instance_.empty()) {
    if (mesh->area_light >= 0) {
      scene_.warnings.push_back(at.where() + ": area lights inside ObjectBegin are not supported (as in pbrt-v4); not emissive");
      mesh->area_light = -1;
    }
    scene_.objects[objects_.at(open_instance_)].meshes.push_back(std::move(*mesh));
  } else {
    check_coordinates(*mesh, at);
    scene_.meshes.push_back(std::move(*mesh));
  }
}

void PbrtParser::resolve_media() {
  std::map<int16_t, int16_t> index;  // code -> medium (-1: not simulated)
  for (const auto& [name, ref] : medium_refs_) {
    auto it = names_.media.find(name);
    if (it == names_.media.end()) throw SceneError(ref.where + ": unknown medium \"" + name + "\" in MediumInterface");
    index[ref.code] = static_cast<int16_t>(it->second);
  }
  auto resolve = [&](int16_t code) -> int16_t { return code <= -2 ? index.at(code) : code; };
  auto resolve_mesh = [&](MeshDesc& m) {
    m.media.inside = resolve(m.media.inside);
    m.media.outside = resolve(m.media.outside);
  };
  for (MeshDesc& m : scene_.meshes) resolve_mesh(m);
  for (ObjectDesc& o : scene_.objects)
    for (MeshDesc& m : o.meshes) resolve_mesh(m);
  scene_.camera_medium = resolve(static_cast<int16_t>(scene_.camera_medium));
  for (Light& l : scene_.lights) l.medium = resolve(static_cast<int16_t>(l.medium));
}

SceneDesc PbrtParser::finish(const std::string& file_name, int last_line) {
  const std::string where = file_name + ":" + std::to_string(last_line);
  if (!world_begun_) throw SceneError(where + ": missing WorldBegin");
  if (!open_instance_.empty()) scene_.warnings.push_back(where + ": ObjectBegin \"" + open_instance_ + "\" not closed");
  for (const StackEntry& e : stack_)
    if (e.kind != 'o') scene_.warnings.push_back(e.where + ": block not closed before end of file");
  settle_instances(scene_);
  if (scene_.meshes.empty() && scene_.instances.empty() && scene_.lights.empty())
    throw SceneError(where + ": empty scene (no shapes and no lights)");
  resolve_media();
  set_film_sensor(scene_.film, scene_.camera.exposure_time);
  return std::move(scene_);
}

}  // namespace tessera
