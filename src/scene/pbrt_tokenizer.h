// Splits pbrt-v4 scene text into tokens, remembering where each came from so
// that every later error can say "file:line".
#pragma once

#include <deque>
#include <istream>
#include <string>
#include <vector>

namespace tessera {

enum class TokenKind { Word, String, Number, OpenBracket, CloseBracket };

struct Token {
  TokenKind kind = TokenKind::Word;
  std::string text;    // String: without the quotes; others: as written
  double number = 0.;  // Number only
  // The file's name, shared by all its tokens (a big mesh is millions of
  // tokens: a copy of the name in each was half their memory).
  const std::string* file = nullptr;
  int line = 0;

  std::string where() const { return (file ? *file : std::string("?")) + ":" + std::to_string(line); }
};

// The tokens of one file, made as the parser asks for them and dropped once
// it has moved past them (release_before), from text read in chunks: a mesh
// of millions of numbers is never held as its text nor as millions of
// tokens. Indices count from the file's first token. Throws SceneError, when
// the parser reaches it, for an unterminated string or a malformed/non-finite
// number ("1.2.3", "1e999"). Words that are not directives (e.g. "nan") are
// left to the parser, which knows whether a number was expected. `in` and
// `file` must outlive the stream and its tokens.
class TokenStream {
 public:
  static constexpr size_t kDefaultChunk = size_t(1) << 20;
  // chunk: bytes read at a time (tests use a few, so that tokens straddle chunks).
  TokenStream(std::istream& in, const std::string& file, size_t chunk = kDefaultChunk)
      : in_(in), file_(file), chunk_(chunk > 0 ? chunk : 1) {}
  // A temporary name would leave the tokens pointing at a freed string.
  TokenStream(std::istream&, std::string&&, size_t = kDefaultChunk) = delete;
  // Whether token `index` exists (making tokens up to it). False past the
  // end, and for tokens already released.
  bool has(size_t index);
  // Token `index`; it must exist. References stay valid until it is released.
  const Token& operator[](size_t index);
  // Drops the tokens before `index`.
  void release_before(size_t index);
  // The file's last line (its line count, at least 1), once has() has
  // returned false at the end.
  int last_line() const;

 private:
  bool produce();  // appends the next token; false at the end of the text
  bool more();     // whether a character is left, reading the next chunk if need be
  // Consumes the characters up to the first one `stop` accepts (or the
  // end), appending them to `out` unless it is null.
  template <typename Stop>
  void take_until(std::string* out, Stop stop);

  std::istream& in_;
  const std::string& file_;
  size_t chunk_;
  std::string buf_;  // the current chunk
  size_t i_ = 0;     // next character in buf_
  bool ends_with_newline_ = false, empty_ = true;
  int line_ = 1;
  size_t first_ = 0;  // index of window_.front()
  std::deque<Token> window_;
};

// Whether `word` is a pbrt-v4 (or legacy v3) directive name: lets the
// parameter reader tell a missing ']' from a stray word.
bool is_pbrt_directive_name(const std::string& word);

}  // namespace tessera
