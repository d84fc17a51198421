#include "scene/pbrt_params.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "scene/named_spectra.h"
#include "scene/scene_desc.h"

namespace tessera {
namespace {

[[noreturn]] void fail(const std::string& where, const std::string& problem) {
  throw SceneError(where + ": " + problem);
}

std::string canonical_type(const std::string& t) {
  if (t == "point") return "point3";
  if (t == "vector") return "vector3";
  if (t == "normal") return "normal3";
  if (t == "color") return "rgb";
  return t;
}

// How many numbers one value of a numeric type takes (0: not numeric).
int numeric_width(const std::string& t) {
  if (t == "integer" || t == "float" || t == "blackbody") return 1;
  if (t == "point2" || t == "vector2") return 2;
  if (t == "point3" || t == "vector3" || t == "normal3" || t == "rgb") return 3;
  return 0;
}

bool is_string_type(const std::string& t) { return t == "string" || t == "texture"; }

// Values appended in blocks that double from a few values up to 1 MiB
// (a one-number parameter costs no more than before; a mesh's arrays come in
// blocks the allocator maps from the system and returns when freed),
// released as one array.
template <typename T>
class BlockArray {
 public:
  void push_back(T v) {
    if (blocks_.empty() || blocks_.back().size() == blocks_.back().capacity()) {
      const size_t next = blocks_.empty() ? 16 : std::min(kBlock, 2 * blocks_.back().capacity());
      blocks_.emplace_back().reserve(next);
    }
    blocks_.back().push_back(v);
  }
  std::vector<T> release() {
    size_t n = 0;
    for (const std::vector<T>& b : blocks_) n += b.size();
    std::vector<T> out;
    out.reserve(n);
    for (std::vector<T>& b : blocks_) {
      out.insert(out.end(), b.begin(), b.end());
      std::vector<T>().swap(b);  // frees the block now (assigning {} would keep its capacity)
    }
    blocks_.clear();
    return out;
  }

 private:
  static constexpr size_t kBlock = (size_t(1) << 20) / sizeof(T);
  std::vector<std::vector<T>> blocks_;
};

}  // namespace

std::vector<Param> parse_param_list(TokenStream& tokens, size_t& pos) {
  std::vector<Param> params;
  while (tokens.has(pos) && tokens[pos].kind == TokenKind::String) {
    const Token decl = tokens[pos++];  // a copy: the array below releases tokens as it reads them
    Param p;
    p.where = decl.where();
    {
      std::istringstream words(decl.text);
      std::string extra;
      if (!(words >> p.type >> p.name) || (words >> extra))
        fail(p.where, "malformed parameter declaration \"" + decl.text + "\" (expected \"type name\")");
    }
    p.type = canonical_type(p.type);
    const int width = numeric_width(p.type);
    const bool numeric = width > 0;
    if (!numeric && !is_string_type(p.type) && p.type != "bool" && p.type != "spectrum")
      fail(p.where, "unknown parameter type '" + p.type + "' in \"" + decl.text + "\"");

    // Numbers are gathered in blocks, then copied once into arrays of exactly
    // their size: a growing vector would hold up to twice a mesh's array,
    // and three times while it moves.
    BlockArray<Float> numbers;
    BlockArray<int32_t> integers;
    // Each value as it is read: one token, or a bracketed array of them,
    // released as it goes (a mesh's array is millions of tokens).
    auto take = [&](const Token& v) {
      if (p.type == "bool") {
        if (v.text == "true") p.bools.push_back(true);
        else if (v.text == "false") p.bools.push_back(false);
        else fail(v.where(), "expected true or false for \"" + decl.text + "\", got '" + v.text + "'");
      } else if (is_string_type(p.type)) {
        if (v.kind != TokenKind::String) fail(v.where(), "expected a quoted string for \"" + decl.text + "\"");
        p.strings.push_back(v.text);
      } else if (p.type == "spectrum" && v.kind == TokenKind::String) {
        p.strings.push_back(v.text);
      } else {
        if (v.kind != TokenKind::Number) fail(v.where(), "malformed number '" + v.text + "' for \"" + decl.text + "\"");
        if (p.type == "integer" && v.number != std::floor(v.number))
          fail(v.where(), "non-integer value '" + v.text + "' for \"" + decl.text + "\"");
        // Integers are read as int: a value beyond its range would convert with undefined behaviour.
        if (p.type == "integer" && !(std::abs(v.number) <= 2147483647.0))
          fail(v.where(), "integer '" + v.text + "' for \"" + decl.text + "\" is out of range");
        if (p.type == "integer") integers.push_back(static_cast<int32_t>(v.number));
        else numbers.push_back(static_cast<Float>(v.number));
      }
    };
    if (!tokens.has(pos)) fail(p.where, "missing value for parameter \"" + decl.text + "\"");
    if (tokens[pos].kind == TokenKind::OpenBracket) {
      const Token open = tokens[pos++];
      bool closed = false;
      while (tokens.has(pos)) {
        const Token& t = tokens[pos];
        if (t.kind == TokenKind::CloseBracket) {
          closed = true;
          ++pos;
          break;
        }
        if (t.kind == TokenKind::OpenBracket || (t.kind == TokenKind::Word && is_pbrt_directive_name(t.text))) break;
        take(t);
        ++pos;
        if ((pos & 4095u) == 0) tokens.release_before(pos);
      }
      if (!closed) fail(open.where(), "unterminated array for parameter \"" + decl.text + "\"");
    } else if (tokens[pos].kind == TokenKind::CloseBracket) {
      fail(tokens[pos].where(), "unexpected ']'");
    } else {
      take(tokens[pos++]);
    }

    p.numbers = numbers.release();
    p.integers = integers.release();
    const size_t count = p.numbers.size() + p.integers.size();
    if (numeric && count % width != 0)
      fail(p.where, "\"" + decl.text + "\" needs a multiple of " + std::to_string(width) + " values, got " +
                        std::to_string(count));
    if (p.type == "spectrum") {
      if (!p.strings.empty() && (p.strings.size() != 1 || !p.numbers.empty()))
        fail(p.where, "\"" + decl.text + "\" takes one named spectrum or wavelength/value pairs");
      if (p.strings.empty() && (p.numbers.empty() || p.numbers.size() % 2 != 0))
        fail(p.where, "\"" + decl.text + "\" needs wavelength/value pairs, got " + std::to_string(p.numbers.size()) +
                          " values");
    }
    // (rgb arrays are pbrt-v4's rgbgrid voxels; get_rgb takes exactly one triple.)
    if (p.type == "blackbody" && p.numbers.size() != static_cast<size_t>(width))
      fail(p.where, "\"" + decl.text + "\" takes exactly " + std::to_string(width) + " values");
    params.push_back(std::move(p));
  }
  return params;
}

const Param* ParamSet::find(const std::string& name, std::initializer_list<const char*> types) const {
  for (const Param& p : params_) {
    if (p.name != name) continue;
    for (const char* t : types) {
      if (p.type == t) {
        p.used = true;
        return &p;
      }
    }
  }
  return nullptr;
}

const Param* ParamSet::find_any(const std::string& name) const {
  for (const Param& p : params_)
    if (p.name == name) {
      p.used = true;
      return &p;
    }
  return nullptr;
}

void ParamSet::release(const std::string& name) const {
  for (const Param& p : params_)
    if (p.name == name) {
      std::vector<Float>().swap(p.numbers);  // assigning {} would keep the capacity
      std::vector<int32_t>().swap(p.integers);
    }
}

Float ParamSet::get_float(const std::string& name, Float fallback) const {
  const Param* p = find(name, {"float"});
  return p && !p->numbers.empty() ? p->numbers[0] : fallback;
}

int ParamSet::get_int(const std::string& name, int fallback) const {
  const Param* p = find(name, {"integer"});
  return p && !p->integers.empty() ? p->integers[0] : fallback;
}

bool ParamSet::get_bool(const std::string& name, bool fallback) const {
  const Param* p = find(name, {"bool"});
  return p && !p->bools.empty() ? p->bools[0] : fallback;
}

std::string ParamSet::get_string(const std::string& name, const std::string& fallback) const {
  const Param* p = find(name, {"string"});
  return p && !p->strings.empty() ? p->strings[0] : fallback;
}

std::optional<Vec3> ParamSet::get_point3(const std::string& name) const {
  const Param* p = find(name, {"point3", "vector3", "normal3"});
  if (!p || p->numbers.size() < 3) return std::nullopt;
  return Vec3(p->numbers[0], p->numbers[1], p->numbers[2]);
}

std::vector<Float> ParamSet::get_floats(const std::string& name) const {
  const Param* p = find(name, {"float"});
  return p ? p->numbers : std::vector<Float>{};
}

const std::vector<int32_t>& ParamSet::get_ints(const std::string& name) const {
  static const std::vector<int32_t> kNone;
  const Param* p = find(name, {"integer"});
  return p ? p->integers : kNone;
}

std::vector<std::string> ParamSet::get_strings(const std::string& name) const {
  const Param* p = find(name, {"string"});
  return p ? p->strings : std::vector<std::string>{};
}

namespace {
std::vector<Vec3> as_vec3s(const Param* p) {
  std::vector<Vec3> out;
  if (!p) return out;
  for (size_t i = 0; i + 2 < p->numbers.size(); i += 3)
    out.emplace_back(p->numbers[i], p->numbers[i + 1], p->numbers[i + 2]);
  return out;
}
}  // namespace

std::vector<Vec3> ParamSet::get_point3s(const std::string& name) const { return as_vec3s(find(name, {"point3"})); }

std::vector<Vec3> ParamSet::get_normals(const std::string& name) const { return as_vec3s(find(name, {"normal3"})); }

std::vector<Vec2> ParamSet::get_point2s(const std::string& name) const {
  std::vector<Vec2> out;
  const Param* p = find(name, {"point2", "vector2", "float"});
  if (!p) return out;
  if (p->numbers.size() % 2 != 0) fail(p->where, "\"" + p->type + " " + name + "\" needs pairs of values");
  for (size_t i = 0; i + 1 < p->numbers.size(); i += 2)
    out.emplace_back(p->numbers[i], p->numbers[i + 1]);
  return out;
}

std::optional<Rgb> ParamSet::get_rgb(const std::string& name, bool allow_float) const {
  const Param* p = allow_float ? find(name, {"rgb", "spectrum", "blackbody", "float"})
                               : find(name, {"rgb", "spectrum", "blackbody"});
  if (!p) return std::nullopt;
  if (p->type == "rgb") {
    if (p->numbers.size() != 3) fail(p->where, "\"rgb " + name + "\" takes exactly 3 values");
    return Rgb(p->numbers[0], p->numbers[1], p->numbers[2]);
  }
  if (p->type == "float") {
    if (p->numbers.empty()) fail(p->where, "\"float " + name + "\" has no value");
    return Rgb(p->numbers[0]);
  }
  if (p->type == "blackbody") return blackbody_rgb(p->numbers[0]);
  // spectrum
  if (!p->strings.empty()) {
    if (auto rgb = named_spectrum_rgb(p->strings[0])) return *rgb;
    fail(p->where, "unknown named spectrum \"" + p->strings[0] + "\"");
  }
  const std::vector<Float>& pairs = p->numbers;
  if (warnings)
    warnings->push_back(p->where + ": \"spectrum " + name + "\" given as samples" +
                        (p->file.empty() ? std::string() : " (file '" + p->file + "')") + "; using an approximate RGB");
  return sampled_spectrum_rgb(pairs);
}

std::vector<Rgb> ParamSet::get_rgbs(const std::string& name) const {
  std::vector<Rgb> out;
  const Param* p = find(name, {"rgb"});
  if (!p) return out;
  for (size_t i = 0; i + 2 < p->numbers.size(); i += 3)
    out.emplace_back(p->numbers[i], p->numbers[i + 1], p->numbers[i + 2]);
  return out;
}

std::optional<std::string> ParamSet::get_texture(const std::string& name) const {
  const Param* p = find(name, {"texture"});
  if (!p || p->strings.empty()) return std::nullopt;
  return p->strings[0];
}

void ParamSet::report_unused(std::vector<std::string>& out) const {
  for (const Param& p : params_)
    if (!p.used) out.push_back(p.where + ": unknown parameter '" + p.name + "' for " + directive_);
}

}  // namespace tessera
