// A directive's parameter list ("float radius" [ 2 ] "rgb L" [ 1 1 1 ] ...),
// with typed look-ups that remember what was asked for, so that parameters no
// code looked at can be reported as unknown.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "kernels/device.h"
#include "scene/pbrt_tokenizer.h"

namespace tessera {

struct Param {
  std::string type;  // as written, e.g. "point3", "rgb", "texture"
  std::string name;
  // Numbers as pbrt-v4 keeps them: "integer" values as int, the rest
  // (point3, rgb, spectrum sample pairs...) as Float.
  // Mutable so that a shape can free a mesh's arrays as soon as it has
  // converted them (ParamSet::release).
  mutable std::vector<Float> numbers;
  mutable std::vector<int32_t> integers;
  std::vector<std::string> strings;  // string, texture, named spectrum
  std::vector<bool> bools;
  std::string where;  // "file:line" of the declaration
  std::string file;   // spectrum read from a file: the name as written (numbers hold its pairs)
  mutable bool used = false;
};

class ParamSet {
 public:
  // `directive` names the owner in messages, e.g. `Shape "sphere"`.
  ParamSet(std::vector<Param> params, std::string directive)
      : params_(std::move(params)), directive_(std::move(directive)) {}
  ParamSet() = default;

  Float get_float(const std::string& name, Float fallback) const;
  int get_int(const std::string& name, int fallback) const;
  bool get_bool(const std::string& name, bool fallback) const;
  std::string get_string(const std::string& name, const std::string& fallback) const;
  std::optional<Vec3> get_point3(const std::string& name) const;  // also "point", "vector3"...
  std::vector<Float> get_floats(const std::string& name) const;
  // The values of an "integer" array, read in place (a mesh's indices are
  // millions); empty if absent.
  const std::vector<int32_t>& get_ints(const std::string& name) const;
  std::vector<std::string> get_strings(const std::string& name) const;
  std::vector<Vec3> get_point3s(const std::string& name) const;
  std::vector<Vec3> get_normals(const std::string& name) const;
  std::vector<Vec2> get_point2s(const std::string& name) const;  // point2 or float pairs (uv)
  // "rgb", "spectrum" (named or sampled) or "blackbody" → linear RGB. A lone
  // "float" is accepted too (grey) where `allow_float`.
  std::optional<Rgb> get_rgb(const std::string& name, bool allow_float = false) const;
  // Every triple of an "rgb" array (pbrt-v4's rgbgrid voxels).
  std::vector<Rgb> get_rgbs(const std::string& name) const;
  // Name of a "texture" parameter, if given.
  std::optional<std::string> get_texture(const std::string& name) const;
  // Frees the numbers of parameter `name` once they have been read (a
  // mesh's "P" and "indices": its arrays are then never held twice over).
  void release(const std::string& name) const;
  // The declaration of `name` whatever its type (marks it used).
  const Param* find_any(const std::string& name) const;

  // "file:line: unknown parameter 'foo' for Shape "sphere"" for every
  // parameter never looked up.
  void mark_all_used() const {
    for (const Param& p : params_) p.used = true;
  }
  void report_unused(std::vector<std::string>& warnings) const;

  const std::string& directive() const { return directive_; }
  std::vector<std::string>* warnings = nullptr;  // where conversions note approximations

 private:
  const Param* find(const std::string& name, std::initializer_list<const char*> types) const;
  std::vector<Param> params_;
  std::string directive_;
};

// Parses the parameter list starting at tokens[pos], advancing pos past it.
// Throws SceneError for malformed declarations, unterminated arrays, values
// of the wrong kind or count.
std::vector<Param> parse_param_list(TokenStream& tokens, size_t& pos);

}  // namespace tessera
