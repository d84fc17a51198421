// What a saved guide's file (either kind) holds around its fields, as a
// checkpoint does: after the kind's magic and its version, the size of the
// payload and its FNV-1a checksum (kernels/fnv1a.h), then the payload (the
// scene fingerprint and the guide's fields). A damaged byte anywhere is
// refused before a field is read; the fields' ranges are the kind's to check.
#pragma once

#include <cstdint>
#include <iosfwd>
#include <string>

namespace tessera {

// The checksum a guide file stores for its payload.
uint64_t guide_payload_checksum(const std::string& payload);

// Reads the `size` bytes of payload that follow the header, which must be
// the rest of the stream, and checks them against `checksum`. Throws
// std::runtime_error naming `what` ("guide cache", "neural guide") when
// the stream ends early, has bytes after the payload, or fails the
// checksum. Memory grows with the bytes really there, not with `size`.
std::string read_guide_payload(std::istream& in, uint64_t size, uint64_t checksum, const std::string& what);

}  // namespace tessera
