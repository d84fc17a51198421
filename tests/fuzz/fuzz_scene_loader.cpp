// libFuzzer target over the scene loader: pbrt-v4 text through the
// tokenizer, parser and loader (meshes, textures, media), as `tessera render`
// reads it. A malformed scene must end in a SceneError or another
// std::exception with a message; a crash, a sanitizer report, a hang or
// runaway memory is a finding. scripts/fuzz.sh builds this with clang,
// ASan and UBSan and runs it; tests/fuzz/replay_main.cpp runs the corpus
// through the same function in the ordinary test suite.
#include <cstddef>
#include <cstdint>
#include <exception>
#include <string>

#include "scene/pbrt_loader.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    // Relative paths (Include, plymesh, imagemap) resolve against a folder
    // with nothing in it: they are missing-file errors.
    tessera::SceneDesc desc = tessera::load_pbrt_string(text, "<fuzz>", "/nonexistent-fuzz-dir");
    (void)desc;
  } catch (const std::exception&) {
    // A clear error is the right answer to bad input.
  }
  return 0;
}
