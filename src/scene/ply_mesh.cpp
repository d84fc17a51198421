// Our own PLY reader. Debian's one PLY-capable library, Assimp, aborts in its
// triangulation on small valid binary meshes, reads past the end of truncated
// ones, loops forever on a header without end_header and cannot read
// .ply.gz; pbrt-v4 embeds a patched RPly, which Debian does not package. The
// format is small, so we read it here from a buffer whose every access is
// bounds-checked, and every element count is checked against the bytes left
// before anything is allocated for it.
#include "scene/ply_mesh.h"

#include <zlib.h>

#include <bit>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <optional>
#include <sstream>

#include "scene/load_stop.h"
#include "scene/scene_desc.h"
#include "scene/system_memory.h"

namespace tessera {
namespace {

static_assert(std::endian::native == std::endian::little, "binary PLY decoding assumes a little-endian host");

// Decompressed files larger than this are refused (a gzip bomb would
// otherwise take all memory before any check could look at it).
constexpr size_t kMaxPlyBytes = size_t(4) << 30;

enum class PlyFormat { Ascii, BinaryLittleEndian, BinaryBigEndian };
enum class PlyType { Int8, UInt8, Int16, UInt16, Int32, UInt32, Float32, Float64 };

struct PlyProperty {
  std::string name;
  PlyType type = PlyType::Float32;  // of the values (a list's entries)
  bool is_list = false;
  PlyType count_type = PlyType::UInt8;  // lists only
};

struct PlyElement {
  std::string name;
  uint64_t count = 0;
  std::vector<PlyProperty> properties;
};

struct PlyHeader {
  PlyFormat format = PlyFormat::Ascii;
  std::vector<PlyElement> elements;
  size_t body_offset = 0;  // first byte after the end_header line
};

class PlyFailure {
 public:
  explicit PlyFailure(const std::string& name) : name_(name) {}
  [[noreturn]] void operator()(const std::string& reason) const {
    throw SceneError("cannot read PLY '" + name_ + "': " + reason);
  }

 private:
  const std::string& name_;
};

size_t type_size(PlyType t) {
  switch (t) {
    case PlyType::Int8: case PlyType::UInt8: return 1;
    case PlyType::Int16: case PlyType::UInt16: return 2;
    case PlyType::Int32: case PlyType::UInt32: case PlyType::Float32: return 4;
    case PlyType::Float64: return 8;
  }
  return 8;
}

std::optional<PlyType> parse_type(const std::string& s) {
  if (s == "char" || s == "int8") return PlyType::Int8;
  if (s == "uchar" || s == "uint8") return PlyType::UInt8;
  if (s == "short" || s == "int16") return PlyType::Int16;
  if (s == "ushort" || s == "uint16") return PlyType::UInt16;
  if (s == "int" || s == "int32") return PlyType::Int32;
  if (s == "uint" || s == "uint32") return PlyType::UInt32;
  if (s == "float" || s == "float32") return PlyType::Float32;
  if (s == "double" || s == "float64") return PlyType::Float64;
  return std::nullopt;
}

std::vector<std::string> split_words(const std::string& line) {
  std::vector<std::string> words;
  std::istringstream in(line);
  for (std::string w; in >> w;) words.push_back(w);
  return words;
}

// A header word for an error message: control bytes (a binary body read as
// header text) written as \xNN, and at most 32 characters.
std::string printable(const std::string& word) {
  std::string out;
  for (size_t i = 0; i < word.size() && i < 32; ++i) {
    const unsigned char c = static_cast<unsigned char>(word[i]);
    if (c < 0x20 || c >= 0x7f) {
      char buf[8];
      std::snprintf(buf, sizeof buf, "\\x%02x", c);
      out += buf;
    } else {
      out += static_cast<char>(c);
    }
  }
  return word.size() > 32 ? out + "..." : out;
}

PlyHeader parse_header(const std::string& bytes, const PlyFailure& fail) {
  PlyHeader h;
  size_t pos = 0, line_number = 0;
  bool have_format = false;
  auto next_line = [&]() -> std::optional<std::string> {
    if (pos >= bytes.size()) return std::nullopt;
    size_t eol = bytes.find('\n', pos);
    if (eol == std::string::npos) eol = bytes.size();
    std::string line = bytes.substr(pos, eol - pos);
    if (!line.empty() && line.back() == '\r') line.pop_back();
    pos = eol == bytes.size() ? eol : eol + 1;  // a last line without '\n' ends at the end
    ++line_number;
    return line;
  };
  std::optional<std::string> first = next_line();
  if (!first || split_words(*first) != std::vector<std::string>{"ply"}) fail("not a PLY file (no 'ply' magic line)");
  for (;;) {
    std::optional<std::string> line = next_line();
    if (!line) fail("header has no end_header line");
    const std::vector<std::string> w = split_words(*line);
    const std::string where = "header line " + std::to_string(line_number) + ": ";
    if (w.empty() || w[0] == "comment" || w[0] == "obj_info") continue;
    if (w[0] == "end_header") break;
    if (w[0] == "format") {
      if (w.size() != 3) fail(where + "expected 'format <kind> <version>'");
      if (w[1] == "ascii") h.format = PlyFormat::Ascii;
      else if (w[1] == "binary_little_endian") h.format = PlyFormat::BinaryLittleEndian;
      else if (w[1] == "binary_big_endian") h.format = PlyFormat::BinaryBigEndian;
      else fail(where + "unknown format '" + printable(w[1]) + "'");
      have_format = true;
    } else if (w[0] == "element") {
      if (w.size() != 3) fail(where + "expected 'element <name> <count>'");
      uint64_t count = 0;
      auto [end, ec] = std::from_chars(w[2].data(), w[2].data() + w[2].size(), count);
      if (ec != std::errc() || end != w[2].data() + w[2].size())
        fail(where + "element count '" + printable(w[2]) + "' is not a non-negative integer");
      h.elements.push_back(PlyElement{w[1], count, {}});
    } else if (w[0] == "property") {
      if (h.elements.empty()) fail(where + "property before any element");
      PlyProperty p;
      if (w.size() == 5 && w[1] == "list") {
        std::optional<PlyType> count_type = parse_type(w[2]), value_type = parse_type(w[3]);
        if (!count_type || !value_type) fail(where + "unknown type in list property '" + printable(w[4]) + "'");
        if (*count_type == PlyType::Float32 || *count_type == PlyType::Float64)
          fail(where + "list property '" + w[4] + "' has a floating-point count type");
        p = PlyProperty{w[4], *value_type, true, *count_type};
      } else if (w.size() == 3 && w[1] != "list") {
        std::optional<PlyType> type = parse_type(w[1]);
        if (!type) fail(where + "unknown property type '" + printable(w[1]) + "'");
        p = PlyProperty{w[2], *type, false, PlyType::UInt8};
      } else {
        fail(where + "expected 'property <type> <name>' or 'property list <count type> <type> <name>'");
      }
      h.elements.back().properties.push_back(p);
    } else {
      fail(where + "unknown keyword '" + printable(w[0]) + "'");
    }
  }
  if (!have_format) fail("header has no format line");
  h.body_offset = pos;
  return h;
}

// The bytes of a PLY file: all in memory, or read through zlib in chunks
// (plain files pass through zlib unchanged) from a file whose total size is
// known before its body is read, so that every count is still checked
// against the bytes left before anything is allocated for it.
class PlyBytes {
 public:
  // A whole file in memory, from `offset` on.
  PlyBytes(const std::string& bytes, size_t offset)
      : data_(bytes.data()), pos_(offset), end_(bytes.size()), left_(offset < bytes.size() ? bytes.size() - offset : 0) {}
  // A file being read: `prefix` holds its bytes from `offset` on as far as
  // read so far, `left` counts every byte from `offset` to the end.
  PlyBytes(gzFile file, std::string prefix, size_t offset, uint64_t left, size_t chunk, const PlyFailure& fail)
      : file_(file), window_(std::move(prefix)), pos_(offset), left_(left), chunk_(chunk), fail_(&fail) {
    // Bytes past the size measured (a file growing while it is read) are not the file's.
    window_.resize(static_cast<size_t>(std::min<uint64_t>(window_.size(), offset + left)));
    data_ = window_.data();
    end_ = window_.size();
  }

  // Makes n bytes available at data(); false when fewer than n are left.
  bool ensure(size_t n) {
    if (end_ - pos_ >= n) return true;
    if (left_ < n || !file_) return false;
    refill(n);
    return true;
  }
  const char* data() const { return data_ + pos_; }
  size_t available() const { return end_ - pos_; }
  void skip(size_t n) {
    pos_ += n;
    left_ -= n;
  }
  uint64_t left() const { return left_; }

 private:
  // Keeps the unread bytes and reads at least up to n of them (a chunk if more are left).
  void refill(size_t n) {
    window_.erase(0, pos_);
    pos_ = 0;
    const size_t want = static_cast<size_t>(std::min<uint64_t>(left_, std::max(n, chunk_)));
    size_t have = window_.size();
    window_.resize(want);
    while (have < want) {
      const int got = gzread(file_, window_.data() + have, static_cast<unsigned>(std::min<size_t>(want - have, 1u << 30)));
      if (got <= 0) (*fail_)("the file changed or could not be read while it was parsed");
      have += static_cast<size_t>(got);
    }
    data_ = window_.data();
    end_ = window_.size();
  }

  gzFile file_ = nullptr;
  std::string window_;
  const char* data_ = nullptr;
  size_t pos_ = 0, end_ = 0;
  uint64_t left_ = 0;  // bytes from data() to the end of the file
  size_t chunk_ = 0;
  const PlyFailure* fail_ = nullptr;
};

// Reads values of the body in order; every read checks the bytes left.
class BodyReader {
 public:
  BodyReader(PlyBytes& bytes, PlyFormat format, const PlyFailure& fail) : in_(bytes), format_(format), fail_(fail) {}

  double read(PlyType type) { return format_ == PlyFormat::Ascii ? read_ascii() : read_binary(type); }

  uint64_t bytes_left() const { return in_.left(); }

  // The fewest bytes one value of `type` can occupy: ASCII values need a
  // character and (but for the last) a separator.
  size_t min_value_bytes(PlyType type) const { return format_ == PlyFormat::Ascii ? 1 : type_size(type); }

 private:
  // No number in a PLY body needs this many characters.
  static constexpr size_t kMaxNumberChars = 512;

  double read_binary(PlyType type) {
    const size_t n = type_size(type);
    if (!in_.ensure(n)) fail_("file is truncated (the body ends inside a value)");
    unsigned char b[8];
    std::memcpy(b, in_.data(), n);
    in_.skip(n);
    if (format_ == PlyFormat::BinaryBigEndian)
      for (size_t i = 0; i < n / 2; ++i) std::swap(b[i], b[n - 1 - i]);
    switch (type) {
      case PlyType::Int8: { int8_t v; std::memcpy(&v, b, 1); return v; }
      case PlyType::UInt8: return b[0];
      case PlyType::Int16: { int16_t v; std::memcpy(&v, b, 2); return v; }
      case PlyType::UInt16: { uint16_t v; std::memcpy(&v, b, 2); return v; }
      case PlyType::Int32: { int32_t v; std::memcpy(&v, b, 4); return v; }
      case PlyType::UInt32: { uint32_t v; std::memcpy(&v, b, 4); return v; }
      case PlyType::Float32: { float v; std::memcpy(&v, b, 4); return v; }
      case PlyType::Float64: { double v; std::memcpy(&v, b, 8); return v; }
    }
    return 0;
  }

  double read_ascii() {
    for (;;) {
      if (!in_.ensure(1)) fail_("file is truncated (fewer values than the header declares)");
      if (!is_space(*in_.data())) break;
      in_.skip(1);
    }
    // The number's characters, made available as one run (at most kMaxNumberChars).
    size_t len = 0;
    for (;;) {
      while (len < in_.available() && !is_space(in_.data()[len])) ++len;
      if (len < in_.available() || len >= kMaxNumberChars || !in_.ensure(len + 1)) break;
    }
    const char* start = in_.data();
    double v = 0;
    auto [ptr, ec] = std::from_chars(start, start + len, v);
    if (ec != std::errc() || ptr != start + len || len >= kMaxNumberChars)
      fail_("malformed number '" + std::string(start, std::min<size_t>(len, 32)) + "' in the body");
    in_.skip(len);
    return v;
  }

  static bool is_space(char c) { return c == ' ' || c == '\t' || c == '\n' || c == '\r' || c == '\v' || c == '\f'; }

  PlyBytes& in_;
  PlyFormat format_;
  const PlyFailure& fail_;
};

// Where each vertex property goes: 0-2 position, 3-5 normal, 6-7 uv, -1 nowhere.
std::vector<int> vertex_slots(const PlyElement& e, bool& has_normals, bool& has_uv, const PlyFailure& fail) {
  auto index_of = [&](const char* name) -> int {
    for (size_t i = 0; i < e.properties.size(); ++i)
      if (!e.properties[i].is_list && e.properties[i].name == name) return static_cast<int>(i);
    return -1;
  };
  std::vector<int> slots(e.properties.size(), -1);
  const char* xyz[3] = {"x", "y", "z"};
  for (int c = 0; c < 3; ++c) {
    int i = index_of(xyz[c]);
    if (i < 0) fail(std::string("vertex element has no '") + xyz[c] + "' property");
    slots[i] = c;
  }
  int nx = index_of("nx"), ny = index_of("ny"), nz = index_of("nz");
  has_normals = nx >= 0 && ny >= 0 && nz >= 0;
  if (has_normals) slots[nx] = 3, slots[ny] = 4, slots[nz] = 5;
  // pbrt-v4's conventions for texture coordinates, in its order of preference.
  const char* uv_names[4][2] = {{"u", "v"}, {"s", "t"}, {"texture_u", "texture_v"}, {"texture_s", "texture_t"}};
  has_uv = false;
  for (auto& pair : uv_names) {
    int u = index_of(pair[0]), v = index_of(pair[1]);
    if (u >= 0 && v >= 0) {
      slots[u] = 6, slots[v] = 7;
      has_uv = true;
      break;
    }
  }
  return slots;
}

// An index as written in the file, for messages (NaN and huge values too).
std::string format_index(double v) {
  if (std::isfinite(v) && std::abs(v) < 9e15 && v == std::floor(v)) return std::to_string(static_cast<long long>(v));
  char text[32];
  std::snprintf(text, sizeof text, "%g", v);
  return text;
}

// A list's length, checked to be a count the remaining bytes can hold.
size_t read_list_length(BodyReader& in, const PlyProperty& p, const PlyFailure& fail) {
  const double len = in.read(p.count_type);
  if (!(len >= 0) || len != std::floor(len)) fail("list property '" + p.name + "' has an invalid length");
  if (len > static_cast<double>(in.bytes_left() / in.min_value_bytes(p.type)))
    fail("file is truncated (list property '" + p.name + "' is longer than the bytes left)");
  return static_cast<size_t>(len);
}

void check_count_fits(const PlyElement& e, const BodyReader& in, const PlyFailure& fail) {
  size_t min_bytes = 0;
  for (const PlyProperty& p : e.properties) min_bytes += in.min_value_bytes(p.is_list ? p.count_type : p.type);
  if (min_bytes == 0) min_bytes = 1;  // an element without properties still must not be counted forever
  if (e.count > in.bytes_left() / min_bytes)
    fail("file is truncated (it declares " + std::to_string(e.count) + " " + e.name + " elements, but only " +
         std::to_string(in.bytes_left()) + " bytes follow)");
}

void read_vertices(const PlyElement& e, BodyReader& in, PlyMesh& out, const PlyFailure& fail) {
  bool has_normals = false, has_uv = false;
  const std::vector<int> slots = vertex_slots(e, has_normals, has_uv, fail);
  out.p.resize(e.count);
  if (has_normals) out.n.resize(e.count);
  if (has_uv) out.uv.resize(e.count);
  for (uint64_t v = 0; v < e.count; ++v) {
    if ((v & 0xffff) == 0) check_load_stop();  // a large mesh takes seconds
    float values[8] = {0, 0, 0, 0, 0, 0, 0, 0};
    for (size_t k = 0; k < e.properties.size(); ++k) {
      const PlyProperty& p = e.properties[k];
      if (p.is_list) {
        for (size_t n = read_list_length(in, p, fail); n > 0; --n) in.read(p.type);
        continue;
      }
      const double value = in.read(p.type);
      if (slots[k] >= 0) values[slots[k]] = static_cast<float>(value);
    }
    for (float value : values)
      if (!std::isfinite(value)) fail("vertex " + std::to_string(v) + " has a non-finite (NaN or Inf) value");
    out.p[v] = Vec3(values[0], values[1], values[2]);
    if (has_normals) out.n[v] = Vec3(values[3], values[4], values[5]);
    if (has_uv) out.uv[v] = Vec2(values[6], values[7]);
  }
}

void read_faces(const PlyElement& e, BodyReader& in, PlyMesh& out, uint64_t vertex_count, const PlyFailure& fail) {
  bool have_indices = false;
  for (const PlyProperty& p : e.properties)
    have_indices |= p.is_list && (p.name == "vertex_indices" || p.name == "vertex_index");
  if (!have_indices) fail("face element has no 'vertex_indices' list");
  // Room for a triangle per face: no growth (and no transient copy) for a
  // triangle mesh. A triangle takes at least 4 bytes of the file.
  out.indices.reserve(3 * static_cast<size_t>(std::min<uint64_t>(e.count, in.bytes_left() / 4 + 1)));
  for (uint64_t f = 0; f < e.count; ++f) {
    if ((f & 0xffff) == 0) check_load_stop();
    for (const PlyProperty& p : e.properties) {
      if (!p.is_list) {
        in.read(p.type);  // e.g. pbrt's face_indices (Ptex face ids): not used
        continue;
      }
      const size_t len = read_list_length(in, p, fail);
      const bool indices = p.name == "vertex_indices" || p.name == "vertex_index";
      uint32_t face[4] = {0, 0, 0, 0};
      for (size_t k = 0; k < len; ++k) {
        const double v = in.read(p.type);
        if (!indices) continue;
        if (!(v >= 0 && v < static_cast<double>(vertex_count)) || v != std::floor(v))
          fail("face " + std::to_string(f) + ": vertex index " + format_index(v) + " out of range (" +
               std::to_string(vertex_count) + " vertices)");
        if (k < 4) face[k] = static_cast<uint32_t>(v);
      }
      if (!indices) continue;
      if (len == 3) {
        out.indices.insert(out.indices.end(), {face[0], face[1], face[2]});
      } else if (len == 4) {
        out.indices.insert(out.indices.end(), {face[0], face[1], face[2], face[0], face[2], face[3]});
        ++out.quads;
      } else {
        ++out.skipped_faces;
      }
    }
  }
}

// Refuses a mesh whose arrays cannot fit in memory before reading its body:
// positions (normals, uv) per vertex, a triangle per face.
void check_arrays_fit(const PlyElement& vertex, const PlyElement& face, const PlyFailure& fail) {
  bool has_normals = false, has_uv = false;
  vertex_slots(vertex, has_normals, has_uv, fail);
  const double per_vertex = sizeof(Vec3) * (1 + has_normals) + (has_uv ? sizeof(Vec2) : 0);
  const double need = static_cast<double>(vertex.count) * per_vertex + static_cast<double>(face.count) * 3 * sizeof(uint32_t);
  const uint64_t bytes = need < 1.8e19 ? static_cast<uint64_t>(need) : UINT64_MAX;
  if (exceeds_memory_limit(bytes))
    fail("its " + std::to_string(vertex.count) + " vertices and " + std::to_string(face.count) + " faces need about " +
         format_bytes(bytes) + ", more than the " + format_bytes(memory_limit_bytes().value_or(0)) +
         " of memory this process may use");
}

// The body after the header, read from `bytes`.
PlyMesh read_body(const PlyHeader& header, PlyBytes& bytes, const PlyFailure& fail) {
  const PlyElement* vertex = nullptr;
  const PlyElement* face = nullptr;
  for (const PlyElement& e : header.elements) {
    if (e.name == "vertex" && !vertex) vertex = &e;
    if (e.name == "face" && !face) face = &e;
  }
  if (!vertex || vertex->count == 0) fail("no vertices");
  if (!face || face->count == 0) fail("no faces");
  PlyMesh out;
  BodyReader in(bytes, header.format, fail);
  // A damaged count is a truncated file; a count the file holds may still be
  // more than memory holds.
  for (const PlyElement& e : header.elements) check_count_fits(e, in, fail);
  check_arrays_fit(*vertex, *face, fail);
  for (const PlyElement& e : header.elements) {
    check_count_fits(e, in, fail);
    if (&e == vertex) {
      read_vertices(e, in, out, fail);
    } else if (&e == face) {
      read_faces(e, in, out, vertex->count, fail);  // indices are checked against the header's count
    } else {
      for (uint64_t i = 0; i < e.count; ++i)
        for (const PlyProperty& p : e.properties) {
          const size_t n = p.is_list ? read_list_length(in, p, fail) : 1;
          for (size_t k = 0; k < n; ++k) in.read(p.type);
        }
    }
  }
  if (out.indices.empty()) fail("no triangles or quads among its faces");
  return out;
}

// The start of a file being read, up to and including its end_header line
// (or all of it, or kMaxHeaderBytes: parse_header then says what is wrong).
constexpr size_t kMaxHeaderBytes = size_t(16) << 20;

std::string read_header_bytes(gzFile file, const PlyFailure& fail) {
  std::string prefix;
  size_t from = 0;  // where a line starting with end_header may begin
  for (;;) {
    const size_t old = prefix.size();
    prefix.resize(old + 65536);
    const int got = gzread(file, prefix.data() + old, 65536);
    if (got < 0) fail("decompression failed");
    prefix.resize(old + static_cast<size_t>(got));
    if (got == 0 || prefix.size() >= kMaxHeaderBytes) return prefix;
    // A line that starts with end_header, complete.
    const size_t at = prefix.find("\nend_header", from);
    if (at != std::string::npos && prefix.find('\n', at + 1) != std::string::npos) return prefix;
    from = at != std::string::npos ? at : prefix.size() - std::min<size_t>(prefix.size(), 10);
  }
}

// The size of the file's content: its size, or its decompressed size
// (decompressed once to count it, at most kMaxPlyBytes).
uint64_t content_size(gzFile file, const std::string& path, const PlyFailure& fail) {
  if (gzdirect(file)) {
    std::error_code ec;
    const uint64_t size = std::filesystem::file_size(path, ec);
    if (ec) fail(ec.message());
    return size;
  }
  uint64_t size = 0;
  std::vector<char> scratch(size_t(1) << 20);
  for (;;) {
    const int n = gzread(file, scratch.data(), static_cast<unsigned>(scratch.size()));
    if (n < 0) {
      int code = 0;
      fail(std::string("decompression failed: ") + gzerror(file, &code));
    }
    if (n == 0) break;
    size += static_cast<uint64_t>(n);
    if (size > kMaxPlyBytes) fail("larger than " + std::to_string(kMaxPlyBytes >> 30) + " GiB");
  }
  if (gzrewind(file) != 0) fail("cannot rewind the file");
  return size;
}

}  // namespace

PlyMesh parse_ply_mesh(const std::string& bytes, const std::string& name) {
  const PlyFailure fail(name);
  const PlyHeader header = parse_header(bytes, fail);
  PlyBytes body(bytes, header.body_offset);
  return read_body(header, body, fail);
}

PlyMesh load_ply_mesh(const std::string& path, size_t chunk_bytes) {
  const PlyFailure fail(path);
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) fail("not a regular file");
  // gzread passes uncompressed files through unchanged, so one path serves both.
  gzFile file = gzopen(path.c_str(), "rb");
  if (!file) fail(std::strerror(errno));
  struct Closer {
    gzFile f;
    ~Closer() { gzclose(f); }
  } closer{file};
  const uint64_t size = content_size(file, path, fail);
  std::string prefix = read_header_bytes(file, fail);
  const PlyHeader header = parse_header(prefix, fail);
  if (header.body_offset > size) fail("the file changed while it was read");
  PlyBytes body(file, std::move(prefix), header.body_offset, size - header.body_offset, std::max<size_t>(chunk_bytes, 1),
                fail);
  return read_body(header, body, fail);
}

}  // namespace tessera
