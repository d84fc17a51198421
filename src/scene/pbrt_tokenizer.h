// Splits pbrt-v4 scene text into tokens, remembering where each came from so
// that every later error can say "file:line".
#pragma once

#include <deque>
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
// it has moved past them (release_before): a mesh of millions of numbers is
// never held as millions of tokens. Indices count from the file's first
// token. Throws SceneError, when the parser reaches it, for an unterminated
// string or a malformed/non-finite number ("1.2.3", "1e999"). Words that are
// not directives (e.g. "nan") are left to the parser, which knows whether a
// number was expected. `text` and `file` must outlive the stream and its
// tokens.
class TokenStream {
 public:
  TokenStream(const std::string& text, const std::string& file) : text_(text), file_(file) {}
  // Temporaries would leave the stream and its tokens pointing at freed strings.
  TokenStream(std::string&&, const std::string&) = delete;
  TokenStream(const std::string&, std::string&&) = delete;
  // Whether token `index` exists (making tokens up to it). False past the
  // end, and for tokens already released.
  bool has(size_t index);
  // Token `index`; it must exist. References stay valid until it is released.
  const Token& operator[](size_t index);
  // Drops the tokens before `index`.
  void release_before(size_t index);

 private:
  bool produce();  // appends the next token; false at the end of the text

  const std::string& text_;
  const std::string& file_;
  size_t i_ = 0;  // next character
  int line_ = 1;
  size_t first_ = 0;  // index of window_.front()
  std::deque<Token> window_;
};

// Whether `word` is a pbrt-v4 (or legacy v3) directive name: lets the
// parameter reader tell a missing ']' from a stray word.
bool is_pbrt_directive_name(const std::string& word);

}  // namespace tessera
