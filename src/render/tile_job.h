// What a tile is: a rectangle of pixels and a range of sample indices. A
// plain struct, apart from the integrator: the farm's messages
// (comm/farm_protocol.h) carry it as raw bytes.
#pragma once

#include <cstdint>

namespace tessera {

struct TileJob {
  int32_t x0 = 0, y0 = 0, x1 = 0, y1 = 0;  // [x0, x1) x [y0, y1)
  uint32_t sample_begin = 0, sample_end = 0;
  uint32_t index = 0;  // the tile's place in the pass: light-path splats are added to the film in this order
};

}  // namespace tessera
