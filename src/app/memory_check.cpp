#include "app/memory_check.h"

#include <sys/resource.h>

#include <cstdio>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "master/film.h"

namespace tessera {
namespace {

std::optional<uint64_t> mem_available_from_proc() {
  std::ifstream f("/proc/meminfo");
  std::string key;
  uint64_t kb = 0;
  std::string unit;
  while (f >> key >> kb >> unit)
    if (key == "MemAvailable:") return kb * 1024ull;
  return std::nullopt;
}

// Virtual memory in use by this process (/proc/self/statm, pages).
std::optional<uint64_t> address_space_in_use() {
  std::ifstream f("/proc/self/statm");
  uint64_t pages = 0;
  if (!(f >> pages)) return std::nullopt;
  return pages * 4096ull;
}

}  // namespace

std::optional<uint64_t> available_memory_bytes() {
  std::optional<uint64_t> avail = mem_available_from_proc();
  rlimit lim{};
  if (getrlimit(RLIMIT_AS, &lim) == 0 && lim.rlim_cur != RLIM_INFINITY) {
    const uint64_t used = address_space_in_use().value_or(0);
    const uint64_t left = lim.rlim_cur > used ? lim.rlim_cur - used : 0;
    avail = avail ? std::min(*avail, left) : left;
  }
  return avail;
}

FilmMemory film_memory(int64_t width, int64_t height, bool light_paths, bool checkpoints) {
  const uint64_t pixels = static_cast<uint64_t>(width) * static_cast<uint64_t>(height);
  FilmMemory m;
  m.film = pixels * (sizeof(PixelAccum) + (light_paths ? sizeof(SplatAccum) : 0));
  // Mean and variance images (3 floats each) and the 8-bit preview.
  m.outputs = pixels * (2 * 3 * sizeof(float) + 3);
  // A checkpoint serialises the film into one buffer, then writes it.
  if (checkpoints) m.outputs = std::max<uint64_t>(m.outputs, m.film);
  return m;
}

std::string format_bytes(uint64_t bytes) {
  char b[32];
  if (bytes >= (1ull << 30)) std::snprintf(b, sizeof b, "%.1f GB", bytes / double(1ull << 30));
  else std::snprintf(b, sizeof b, "%.0f MB", bytes / double(1ull << 20));
  return b;
}

void check_film_memory(int64_t width, int64_t height, bool light_paths, bool checkpoints) {
  const std::optional<uint64_t> avail = available_memory_bytes();
  if (!avail) return;
  const FilmMemory need = film_memory(width, height, light_paths, checkpoints);
  if (need.total() <= *avail / 10 * 9) return;
  throw std::runtime_error(std::to_string(width) + "x" + std::to_string(height) + " needs about " +
                           format_bytes(need.total()) + " for its film (" + format_bytes(need.film) +
                           ") and output images (" + format_bytes(need.outputs) + "), but only " +
                           format_bytes(*avail) + " of memory is available: lower --res");
}

}  // namespace tessera
