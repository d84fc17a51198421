#include "guidecache/guide_file.h"

#include <algorithm>
#include <istream>
#include <limits>
#include <stdexcept>

#include "kernels/fnv1a.h"

namespace tessera {

uint64_t guide_payload_checksum(const std::string& payload) { return fnv1a(payload.data(), payload.size()); }

std::string read_guide_payload(std::istream& in, uint64_t size, uint64_t checksum, const std::string& what) {
  constexpr uint64_t kChunk = 1ull << 20;
  std::string payload;
  while (payload.size() < size) {
    const size_t at = payload.size();
    const size_t want = static_cast<size_t>(std::min<uint64_t>(kChunk, size - at));
    payload.resize(at + want);
    in.read(payload.data() + at, static_cast<std::streamsize>(want));
    const size_t got = static_cast<size_t>(in.gcount());
    if (got < want)
      throw std::runtime_error("truncated " + what + " (" + std::to_string(at + got) + " of its " + std::to_string(size) +
                               " payload bytes)");
  }
  if (in.peek() != std::istream::traits_type::eof()) {
    in.ignore(std::numeric_limits<std::streamsize>::max());
    const uint64_t extra = static_cast<uint64_t>(in.gcount());
    throw std::runtime_error("corrupt " + what + " (" + std::to_string(extra) + (extra == 1 ? " byte" : " bytes") +
                             " after its end)");
  }
  in.clear();
  if (guide_payload_checksum(payload) != checksum) throw std::runtime_error("corrupt " + what + " (checksum mismatch)");
  return payload;
}

}  // namespace tessera
