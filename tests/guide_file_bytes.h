// Damaging one field of a saved table guide (guidecache/table/guide_io.cpp)
// while keeping its checksum right, so that a test reaches the range checks
// behind it; and rewriting a file as the version 4 that had no checksum.
#pragma once

#include <cstdint>
#include <cstring>
#include <stdexcept>
#include <string>

#include "guidecache/guide_file.h"

namespace tessera::testing {

// Version 5: the magic (20 bytes), cereal's endianness byte, the version
// (4), the payload's size (8) and checksum (8), then the payload.
constexpr size_t kGuideVersionAt = 21;
constexpr size_t kGuidePayloadAt = 41;
// Offsets in the payload (its own endianness byte, the fingerprint, then
// GuideConfig: grid, budget, split threshold, depth, then the floats below).
constexpr size_t kGuideGridAt = 9;
constexpr size_t kGuideProbAt = 33;
constexpr size_t kGuideFloorAt = 41;
constexpr size_t kGuideNeeMinProbAt = 57;
constexpr size_t kGuideFixedScaleAt = 86;
constexpr size_t kGuideNodesAt = 94;  // the node count (8 bytes), then (child, cell) per node

template <class T>
T guide_payload_get(const std::string& file, size_t at) {
  T v;
  std::memcpy(&v, file.data() + kGuidePayloadAt + at, sizeof v);
  return v;
}

// The file with its size and checksum made right for its payload.
inline std::string guide_resealed(std::string file) {
  const std::string payload = file.substr(kGuidePayloadAt);
  const uint64_t size = payload.size(), checksum = guide_payload_checksum(payload);
  std::memcpy(file.data() + kGuidePayloadAt - 16, &size, 8);
  std::memcpy(file.data() + kGuidePayloadAt - 8, &checksum, 8);
  return file;
}

// The file with the payload's bytes at `at` set to v, checksum kept right.
template <class T>
std::string guide_payload_set(std::string file, size_t at, T v) {
  if (guide_payload_get<uint32_t>(file, kGuideGridAt) < 2) throw std::logic_error("not the layout guide_file_bytes.h knows");
  std::memcpy(file.data() + kGuidePayloadAt + at, &v, sizeof v);
  return guide_resealed(file);
}

// Payload offsets of node i's (child, cell), of value_[entry], and of the split count.
inline size_t guide_node_at(size_t i) { return kGuideNodesAt + 8 + 8 * i; }
inline size_t guide_value_at(const std::string& file, size_t entry) {
  const uint64_t nodes = guide_payload_get<uint64_t>(file, kGuideNodesAt);
  return kGuideNodesAt + 8 + 8 * nodes + 8 + nodes + 8 + 4 * entry;  // nodes, depths, then the values' count
}
inline size_t guide_splits_at(const std::string& file) {
  return file.size() - kGuidePayloadAt - 8 - 1 - 8;  // before the budget flag and the mixture rejections
}

// The same fields as version 4 wrote them: no size or checksum, the
// fingerprint in the header.
inline std::string guide_as_version4(const std::string& file) {
  const uint32_t four = 4;
  std::string v4 = file.substr(0, kGuideVersionAt);
  v4.append(reinterpret_cast<const char*>(&four), 4);
  v4 += file.substr(kGuidePayloadAt + 1);
  return v4;
}

}  // namespace tessera::testing
