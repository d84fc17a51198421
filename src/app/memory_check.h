// Refuses a render whose image cannot fit in memory before it starts,
// instead of failing with std::bad_alloc after the render (the output
// images are allocated at the end): the film's accumulators, their copies
// and the images written from it are counted against the memory the process
// may use.
#pragma once

#include <cstdint>
#include <optional>
#include <string>

#include "scene/system_memory.h"

namespace tessera {

struct FilmMemory {
  uint64_t film = 0;     // per-pixel accumulators (and light-path splats), every copy held at once
  uint64_t outputs = 0;  // mean and variance images, preview, checkpoint payload
  uint64_t total() const { return film + outputs; }
};

// extra_films: further copies of the film held while rendering (a resumed
// checkpoint's, --guide auto's trial snapshot).
FilmMemory film_memory(int64_t width, int64_t height, bool light_paths, bool checkpoints, uint32_t extra_films);

// Throws a one-line error naming the resolution and both figures when the
// film cannot fit in all the memory the process may use (physical plus
// swap, or ulimit -v), with a tenth held back for the scene and everything
// else; warns when it exceeds the memory free now.
void check_film_memory(int64_t width, int64_t height, bool light_paths, bool checkpoints, uint32_t extra_films);

// What a loaded scene still needs before rendering: per triangle its flat
// arrays (indices, face normal, material and light, media, alpha) and its
// share of the BVH, per vertex its position, normal and uv, per instance its
// placement and its Embree instance and top-level BVH entry, counted high
// (scripts/bench_mesh_load.py measures what a mesh takes). Instanced
// geometry counts once, as it is stored once.
constexpr uint64_t kBytesPerInstance = 2048;
uint64_t scene_build_memory(uint64_t triangles, uint64_t vertices, uint64_t instances = 0);

// The same refusal and warning as check_film_memory, for the scene's
// triangles and instances, before their arrays and BVH are built.
void check_scene_memory(uint64_t triangles, uint64_t vertices, uint64_t instances = 0);

}  // namespace tessera
