#include "scene/pbrt_tokenizer.h"

#include <algorithm>
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

bool TokenStream::more() {
  if (i_ < buf_.size()) return true;
  buf_.resize(chunk_);
  in_.read(buf_.data(), static_cast<std::streamsize>(chunk_));
  buf_.resize(static_cast<size_t>(in_.gcount()));
  i_ = 0;
  if (in_.bad()) throw SceneError(file_ + ":" + std::to_string(line_) + ": cannot read the file");
  if (buf_.empty()) return false;
  empty_ = false;
  ends_with_newline_ = buf_.back() == '\n';
  return true;
}

template <typename Stop>
void TokenStream::take_until(std::string* out, Stop stop) {
  while (more()) {
    const size_t start = i_;
    while (i_ < buf_.size() && !stop(buf_[i_])) ++i_;
    if (out) out->append(buf_, start, i_ - start);
    if (i_ < buf_.size()) return;
  }
}

int TokenStream::last_line() const { return std::max(1, empty_ || ends_with_newline_ ? line_ - 1 : line_); }

bool TokenStream::produce() {
  auto fail = [&](int at_line, const std::string& problem) {
    throw SceneError(file_ + ":" + std::to_string(at_line) + ": " + problem);
  };
  while (more()) {
    char c = buf_[i_];
    if (c == '\n') {
      ++line_;
      ++i_;
    } else if (std::isspace(static_cast<unsigned char>(c))) {
      ++i_;
    } else if (c == '#') {
      take_until(nullptr, [](char d) { return d == '\n'; });  // a comment is the rest of its line
    } else if (c == '[' || c == ']') {
      window_.push_back({c == '[' ? TokenKind::OpenBracket : TokenKind::CloseBracket, std::string(1, c), 0., &file_, line_});
      ++i_;
      return true;
    } else if (c == '"') {
      const int start_line = line_;
      std::string s;
      ++i_;
      bool closed = false;
      while (more()) {
        char d = buf_[i_++];
        if (d == '"') {
          closed = true;
          break;
        }
        // pbrt strings cannot span lines; a newline means the quote was never closed.
        if (d == '\n') break;
        if (d == '\\' && more()) {
          char e = buf_[i_++];
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
      window_.push_back({TokenKind::String, std::move(s), 0., &file_, start_line});
      return true;
    } else {
      std::string word;
      take_until(&word, is_delimiter);
      if (starts_number(word[0])) {
        errno = 0;
        char* end = nullptr;
        double v = std::strtod(word.c_str(), &end);
        if (end != word.c_str() + word.size()) fail(line_, "malformed number '" + word + "'");
        // Scene values end up as floats: anything beyond float range is an overflow.
        if (!std::isfinite(v) || std::fabs(v) > std::numeric_limits<float>::max())
          fail(line_, "number out of range '" + word + "'");
        window_.push_back({TokenKind::Number, std::move(word), v, &file_, line_});
      } else {
        window_.push_back({TokenKind::Word, std::move(word), 0., &file_, line_});
      }
      return true;
    }
  }
  return false;
}

bool TokenStream::has(size_t index) {
  while (first_ + window_.size() <= index)
    if (!produce()) return false;
  return index >= first_;
}

const Token& TokenStream::operator[](size_t index) {
  if (!has(index)) throw SceneError(file_ + ":" + std::to_string(line_) + ": read past the end of the file");
  return window_[index - first_];
}

void TokenStream::release_before(size_t index) {
  while (first_ < index && !window_.empty()) {
    window_.pop_front();
    ++first_;
  }
}

}  // namespace tessera
