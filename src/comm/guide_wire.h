// A guide as the farm sends it: Guide::save's bytes (either kind), read
// back by load_guide. The master sends them to every rank at the start, to a
// rank that missed a fold, and keeps them for its stand-ins (master/stand_in.h).
#pragma once

#include <cstdint>
#include <memory>

#include "comm/transport.h"
#include "guidecache/guide.h"

namespace tessera {

Bytes guide_to_bytes(const Guide& guide, uint64_t scene_fingerprint);
// Throws std::runtime_error for bytes that are no guide of this scene.
std::unique_ptr<Guide> guide_from_bytes(const Bytes& bytes, uint64_t scene_fingerprint);

}  // namespace tessera
