#include "app/memory_check.h"

#include <algorithm>
#include <cstdio>
#include <stdexcept>

#include "render/film.h"

namespace tessera {

FilmMemory film_memory(int64_t width, int64_t height, bool light_paths, bool checkpoints, uint32_t extra_films) {
  const uint64_t pixels = static_cast<uint64_t>(width) * static_cast<uint64_t>(height);
  FilmMemory m;
  m.film = pixels * (sizeof(PixelAccum) + (light_paths ? sizeof(SplatAccum) : 0)) * (1 + extra_films);
  // Mean and variance images (3 floats each) and the 8-bit preview.
  m.outputs = pixels * (2 * 3 * sizeof(float) + 3);
  // A checkpoint serialises the film into one buffer, then writes it.
  if (checkpoints) m.outputs = std::max<uint64_t>(m.outputs, m.film);
  return m;
}

uint64_t scene_build_memory(uint64_t triangles, uint64_t vertices, uint64_t instances) {
  return triangles * 128 + vertices * 32 + instances * kBytesPerInstance;
}

void check_scene_memory(uint64_t triangles, uint64_t vertices, uint64_t instances) {
  const uint64_t need = scene_build_memory(triangles, vertices, instances);
  const std::string what = "the scene's " + std::to_string(triangles) + " triangles" +
                           (instances ? " and " + std::to_string(instances) + " instances" : std::string()) +
                           " need about " + format_bytes(need) + " for their arrays and BVH";
  if (exceeds_memory_limit(need))
    throw std::runtime_error(what + ", more than the " + format_bytes(*memory_limit_bytes()) +
                             " of memory this process may use");
  const std::optional<uint64_t> avail = available_memory_bytes();
  if (avail && need > *avail)
    std::fprintf(stderr, "tessera: warning: %s, more than the %s of memory available now\n", what.c_str(),
                 format_bytes(*avail).c_str());
}

void check_film_memory(int64_t width, int64_t height, bool light_paths, bool checkpoints, uint32_t extra_films) {
  const FilmMemory need = film_memory(width, height, light_paths, checkpoints, extra_films);
  const std::string what = std::to_string(width) + "x" + std::to_string(height) + " needs about " +
                           format_bytes(need.total()) + " for its film (" + format_bytes(need.film) +
                           ") and output images (" + format_bytes(need.outputs) + ")";
  // Beyond all the memory there is (swap and ulimit -v included): refused.
  if (exceeds_memory_limit(need.total()))
    throw std::runtime_error(what + ", more than the " + format_bytes(*memory_limit_bytes()) +
                             " of memory this process may use: lower --res");
  // Beyond what is free now: it may still fit once caches are dropped or
  // memory is swapped out, so only a warning.
  const std::optional<uint64_t> avail = available_memory_bytes();
  if (avail && need.total() > *avail)
    std::fprintf(stderr, "tessera: warning: %s, more than the %s of memory available now\n", what.c_str(),
                 format_bytes(*avail).c_str());
}
}  // namespace tessera
