#include "app/memory_check.h"

#include <sys/resource.h>
#include <unistd.h>

#include <cstdio>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "master/film.h"

namespace tessera {
namespace {

// A /proc/meminfo field in bytes.
std::optional<uint64_t> meminfo(const std::string& field) {
  std::ifstream f("/proc/meminfo");
  std::string key, unit;
  uint64_t kb = 0;
  while (f >> key >> kb >> unit)
    if (key == field + ":") return kb * 1024ull;
  return std::nullopt;
}

// Virtual memory in use by this process (/proc/self/statm, pages).
std::optional<uint64_t> address_space_in_use() {
  std::ifstream f("/proc/self/statm");
  uint64_t pages = 0;
  if (!(f >> pages)) return std::nullopt;
  return pages * static_cast<uint64_t>(sysconf(_SC_PAGESIZE));
}

// What the address-space limit (ulimit -v) leaves; nullopt without one.
std::optional<uint64_t> address_space_left() {
  rlimit lim{};
  if (getrlimit(RLIMIT_AS, &lim) != 0 || lim.rlim_cur == RLIM_INFINITY) return std::nullopt;
  const uint64_t used = address_space_in_use().value_or(0);
  return lim.rlim_cur > used ? lim.rlim_cur - used : 0;
}

std::optional<uint64_t> min_of(std::optional<uint64_t> a, std::optional<uint64_t> b) {
  if (a && b) return std::min(*a, *b);
  return a ? a : b;
}

}  // namespace

std::optional<uint64_t> available_memory_bytes() { return min_of(meminfo("MemAvailable"), address_space_left()); }

std::optional<uint64_t> memory_limit_bytes() {
  std::optional<uint64_t> total = meminfo("MemTotal");
  if (total) *total += meminfo("SwapTotal").value_or(0);
  return min_of(total, address_space_left());
}

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

std::string format_bytes(uint64_t bytes) {
  char b[32];
  if (bytes >= (1ull << 30)) std::snprintf(b, sizeof b, "%.1f GB", bytes / double(1ull << 30));
  else std::snprintf(b, sizeof b, "%.0f MB", bytes / double(1ull << 20));
  return b;
}

uint64_t scene_build_memory(uint64_t triangles, uint64_t vertices) { return triangles * 128 + vertices * 32; }

void check_scene_memory(uint64_t triangles, uint64_t vertices) {
  const uint64_t need = scene_build_memory(triangles, vertices);
  const std::string what = "the scene's " + std::to_string(triangles) + " triangles need about " + format_bytes(need) +
                           " for their arrays and BVH";
  const std::optional<uint64_t> limit = memory_limit_bytes();
  if (limit && need > *limit / 10 * 9)
    throw std::runtime_error(what + ", more than the " + format_bytes(*limit) + " of memory this process may use");
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
  const std::optional<uint64_t> limit = memory_limit_bytes();
  if (limit && need.total() > *limit / 10 * 9)
    throw std::runtime_error(what + ", more than the " + format_bytes(*limit) + " of memory this process may use: lower --res");
  // Beyond what is free now: it may still fit once caches are dropped or
  // memory is swapped out, so only a warning.
  const std::optional<uint64_t> avail = available_memory_bytes();
  if (avail && need.total() > *avail)
    std::fprintf(stderr, "tessera: warning: %s, more than the %s of memory available now\n", what.c_str(),
                 format_bytes(*avail).c_str());
}
}  // namespace tessera
