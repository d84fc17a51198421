// The tokenizer reads scene text in chunks: whatever the chunk size, every
// token, its line and the file's last line are those of the whole text
// (words, numbers, strings with escapes and comments straddle chunks when
// they are a few bytes long), and its errors name the same lines.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "scene/pbrt_tokenizer.h"
#include "scene/scene_desc.h"

namespace tessera {
namespace {

struct Read {
  std::vector<Token> tokens;
  int last_line = 0;
  std::string error;
};

Read read_all(const std::string& text, size_t chunk) {
  static const std::string file = "t.pbrt";
  std::istringstream in(text);
  TokenStream ts(in, file, chunk);
  Read r;
  try {
    for (size_t i = 0; ts.has(i); ++i) {
      r.tokens.push_back(ts[i]);
      ts.release_before(i);
    }
    r.last_line = ts.last_line();
  } catch (const SceneError& e) {
    r.error = e.what();
  }
  return r;
}

void expect_same(const Read& a, const Read& b) {
  ASSERT_EQ(a.error, b.error);
  ASSERT_EQ(a.tokens.size(), b.tokens.size());
  for (size_t i = 0; i < a.tokens.size(); ++i) {
    EXPECT_EQ(a.tokens[i].kind, b.tokens[i].kind) << i;
    EXPECT_EQ(a.tokens[i].text, b.tokens[i].text) << i;
    EXPECT_EQ(a.tokens[i].number, b.tokens[i].number) << i;
    EXPECT_EQ(a.tokens[i].line, b.tokens[i].line) << i;
  }
  EXPECT_EQ(a.last_line, b.last_line);
}

TEST(Tokenizer, ChunkSizeChangesNothing) {
  const std::string text =
      "# a comment that is long enough to cross several small chunks\n"
      "LookAt 0 0 -5.25e+0  0 0 0   0 1 0\n"
      "Shape \"trianglemesh\" \"point3 P\" [ -1 -1 0  1 -1 0  0 1 0 ] \"integer indices\" [0 1 2]\n"
      "Texture \"a \\\"quoted\\\" name\" \"spectrum\" \"imagemap\" \"string filename\" \"tab\\there\"\n"
      "\tAttributeBegin#comment right after a word\r\n"
      "  AttributeEnd";  // no newline at the end
  const Read whole = read_all(text, TokenStream::kDefaultChunk);
  ASSERT_EQ(whole.error, "");
  ASSERT_GT(whole.tokens.size(), 30u);
  EXPECT_EQ(whole.last_line, 6);
  for (size_t chunk : {1, 2, 3, 7, 64}) {
    SCOPED_TRACE(chunk);
    expect_same(read_all(text, chunk), whole);
  }
  // A last line ending in a newline is still that line.
  EXPECT_EQ(read_all(text + "\n", 3).last_line, 6);
  EXPECT_EQ(read_all("", 3).last_line, 1);
}

TEST(Tokenizer, ErrorsNameTheSameLineWhateverTheChunks) {
  for (const std::string& text : {std::string("WorldBegin\nShape \"sphere\n"), std::string("Translate 1 2\n\n 3.4.5 6\n"),
                                 std::string("Scale 1e999 1 1\n")}) {
    const Read whole = read_all(text, TokenStream::kDefaultChunk);
    ASSERT_NE(whole.error, "") << text;
    for (size_t chunk : {1, 2, 5}) expect_same(read_all(text, chunk), whole);
  }
  EXPECT_NE(read_all("WorldBegin\nShape \"sphere\n", 1).error.find("t.pbrt:2: unterminated string"), std::string::npos);
}

}  // namespace
}  // namespace tessera
