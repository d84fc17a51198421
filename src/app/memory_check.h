// Refuses a render whose image cannot fit in memory before it starts,
// instead of failing with std::bad_alloc after the render (the output
// images are allocated at the end): the film's accumulators and the images
// written from it are counted against the memory the process may still use.
#pragma once

#include <cstdint>
#include <optional>
#include <string>

namespace tessera {

// Memory this process can still allocate: the smaller of the system's
// available memory (/proc/meminfo MemAvailable) and what the address-space
// limit (ulimit -v) leaves; nullopt when neither can be read.
std::optional<uint64_t> available_memory_bytes();

struct FilmMemory {
  uint64_t film = 0;     // per-pixel accumulators (and light-path splats)
  uint64_t outputs = 0;  // mean and variance images, preview, checkpoint payload
  uint64_t total() const { return film + outputs; }
};

FilmMemory film_memory(int64_t width, int64_t height, bool light_paths, bool checkpoints);

// Throws a one-line error naming the resolution and both figures when the
// film needs more than the memory available (with a tenth held back for
// the scene and everything else).
void check_film_memory(int64_t width, int64_t height, bool light_paths, bool checkpoints);

// "1.5 GB"
std::string format_bytes(uint64_t bytes);

}  // namespace tessera
