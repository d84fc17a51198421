// libFuzzer target over the PLY reader, differential: each input is parsed
// whole from memory and also read from a file in 7-byte chunks (the path
// `plymesh` takes, where values and the header's end straddle chunks, and
// through zlib). Both must give the same mesh or both a SceneError (but for
// gzip streams, which only the file path decompresses); a crash,
// a sanitizer report, a hang, runaway memory or a disagreement is a finding.
// scripts/fuzz.sh builds this with clang, ASan and UBSan and runs it;
// tests/fuzz/replay_main.cpp runs tests/fuzz/ply_corpus through it in the
// ordinary test suite.
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <optional>
#include <string>

#include "scene/ply_mesh.h"
#include "scene/scene_desc.h"

namespace {

std::optional<tessera::PlyMesh> read_or_refuse(const auto& read) {
  try {
    return read();
  } catch (const tessera::SceneError&) {
    return std::nullopt;
  }
}

bool same(const tessera::PlyMesh& a, const tessera::PlyMesh& b) {
  return a.p == b.p && a.n == b.n && a.uv == b.uv && a.indices == b.indices && a.skipped_faces == b.skipped_faces;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string bytes(reinterpret_cast<const char*>(data), size);
  static const std::string path = "/tmp/tessera-fuzz-ply-" + std::to_string(getpid()) + ".ply";
  std::ofstream(path, std::ios::binary | std::ios::trunc) << bytes;
  const auto whole = read_or_refuse([&] { return tessera::parse_ply_mesh(bytes, "<fuzz>"); });
  const auto chunked = read_or_refuse([&] { return tessera::load_ply_mesh(path, 7); });
  std::remove(path.c_str());
  // A gzip stream is decompressed from a file only: there the two differ by design.
  const bool gzip = size >= 2 && data[0] == 0x1f && data[1] == 0x8b;
  if (!gzip && (whole.has_value() != chunked.has_value() || (whole && !same(*whole, *chunked)))) {
    std::fprintf(stderr, "PLY read whole and in chunks disagree (%s whole, %s in chunks)\n",
                 whole ? "a mesh" : "an error", chunked ? "a mesh" : "an error");
    std::abort();
  }
  return 0;
}
