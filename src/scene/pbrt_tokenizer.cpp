#include "scene/pbrt_tokenizer.h"

#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <limits>

#include "scene/scene_desc.h"

namespace tessera {
namespace {

bool starts_number(char c) { return std::isdigit(static_cast<unsigned char>(c)) || c == '-' || c == '+' || c == '.'; }

bool is_delimiter(char c) {
  return std::isspace(static_cast<unsigned char>(c)) || c == '"' || c == '[' || c == ']' || c == '#';
}

}  // namespace

bool is_pbrt_directive_name(const std::string& word) {
  static const char* const kNames[] = {
      "Accelerator", "ActiveTransform", "AreaLightSource", "Attribute", "AttributeBegin", "AttributeEnd",
      "Camera", "ColorSpace", "ConcatTransform", "CoordinateSystem", "CoordSysTransform", "Film",
      "Identity", "Import", "Include", "Integrator", "LightSource", "LookAt", "MakeNamedMaterial",
      "MakeNamedMedium", "Material", "MediumInterface", "NamedMaterial", "ObjectBegin", "ObjectEnd",
      "ObjectInstance", "Option", "PixelFilter", "ReverseOrientation", "Rotate", "Sampler", "Scale",
      "Shape", "Texture", "Transform", "TransformBegin", "TransformEnd", "TransformTimes", "Translate",
      "WorldBegin", "WorldEnd"};
  for (const char* n : kNames)
    if (word == n) return true;
  return false;
}

std::vector<Token> tokenize_pbrt(const std::string& text, const std::string& file) {
  std::vector<Token> tokens;
  // Room for every run of non-blanks and bracket up front: a mesh of
  // millions of numbers otherwise peaks at twice its tokens while the vector
  // grows.
  size_t estimate = 0;
  bool blank = true, comment = false;
  for (const char ch : text) {
    if (comment) {
      comment = ch != '\n';
      continue;
    }
    comment = ch == '#';
    const bool b = comment || std::isspace(static_cast<unsigned char>(ch)) != 0;
    estimate += (blank && !b) + (ch == '[' || ch == ']');
    blank = b;
  }
  tokens.reserve(estimate);
  int line = 1;
  size_t i = 0;
  const size_t n = text.size();
  auto fail = [&](int at_line, const std::string& problem) {
    throw SceneError(file + ":" + std::to_string(at_line) + ": " + problem);
  };
  while (i < n) {
    char c = text[i];
    if (c == '\n') {
      ++line;
      ++i;
    } else if (std::isspace(static_cast<unsigned char>(c))) {
      ++i;
    } else if (c == '#') {
      while (i < n && text[i] != '\n') ++i;
    } else if (c == '[' || c == ']') {
      tokens.push_back({c == '[' ? TokenKind::OpenBracket : TokenKind::CloseBracket, std::string(1, c), 0., &file, line});
      ++i;
    } else if (c == '"') {
      const int start_line = line;
      std::string s;
      ++i;
      bool closed = false;
      while (i < n) {
        char d = text[i++];
        if (d == '"') {
          closed = true;
          break;
        }
        // pbrt strings cannot span lines; a newline means the quote was never closed.
        if (d == '\n') break;
        if (d == '\\' && i < n) {
          char e = text[i++];
          switch (e) {
            case 'n': s += '\n'; break;
            case 't': s += '\t'; break;
            default: s += e; break;
          }
          continue;
        }
        s += d;
      }
      if (!closed) fail(start_line, "unterminated string");
      tokens.push_back({TokenKind::String, std::move(s), 0., &file, start_line});
    } else {
      size_t start = i;
      while (i < n && !is_delimiter(text[i])) ++i;
      std::string word = text.substr(start, i - start);
      if (starts_number(word[0])) {
        errno = 0;
        char* end = nullptr;
        double v = std::strtod(word.c_str(), &end);
        if (end != word.c_str() + word.size()) fail(line, "malformed number '" + word + "'");
        // Scene values end up as floats: anything beyond float range is an overflow.
        if (!std::isfinite(v) || std::fabs(v) > std::numeric_limits<float>::max())
          fail(line, "number out of range '" + word + "'");
        tokens.push_back({TokenKind::Number, std::move(word), v, &file, line});
      } else {
        tokens.push_back({TokenKind::Word, std::move(word), 0., &file, line});
      }
    }
  }
  return tokens;
}

}  // namespace tessera
