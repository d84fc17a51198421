// FNV-1a, 64 bits: the checksum of saved files (checkpoints, guide files)
// and the scene's fingerprint. Every step is a bijection of the state, so
// any one changed byte changes the result; not a cryptographic hash.
#pragma once

#include <cstddef>
#include <cstdint>

namespace tessera {

struct Fnv1a {
  uint64_t h = 0xcbf29ce484222325ull;
  void add(const void* data, size_t n) {
    const auto* b = static_cast<const unsigned char*>(data);
    for (size_t i = 0; i < n; ++i) h = (h ^ b[i]) * 0x100000001b3ull;
  }
};

inline uint64_t fnv1a(const void* data, size_t n) {
  Fnv1a f;
  f.add(data, n);
  return f.h;
}

}  // namespace tessera
