#include "comm/guide_wire.h"

#include <istream>
#include <ostream>

#include "comm/wire.h"

namespace tessera {

Bytes guide_to_bytes(const Guide& guide, uint64_t scene_fingerprint) {
  Bytes bytes;
  BytesOut buffer(bytes);
  std::ostream s(&buffer);
  guide.save(s, scene_fingerprint);
  return bytes;
}

std::unique_ptr<Guide> guide_from_bytes(const Bytes& bytes, uint64_t scene_fingerprint) {
  BytesIn buffer(bytes);
  std::istream s(&buffer);
  return load_guide(s, scene_fingerprint);
}

}  // namespace tessera
