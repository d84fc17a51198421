// Splits pbrt-v4 scene text into tokens, remembering where each came from so
// that every later error can say "file:line".
#pragma once

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

// The tokens point at `file`, which must outlive them. Throws SceneError for an unterminated string or a malformed/non-finite
// number ("1.2.3", "1e999"). Words that are not directives (e.g. "nan") are
// left to the parser, which knows whether a number was expected.
std::vector<Token> tokenize_pbrt(const std::string& text, const std::string& file);

// Whether `word` is a pbrt-v4 (or legacy v3) directive name: lets the
// parameter reader tell a missing ']' from a stray word.
bool is_pbrt_directive_name(const std::string& word);

}  // namespace tessera
