#include "scene/system_memory.h"

#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <fstream>

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

// A /proc/self/status field ("VmRSS") in bytes.
std::optional<uint64_t> status_field(const std::string& field) {
  std::ifstream f("/proc/self/status");
  for (std::string line; std::getline(f, line);)
    if (line.rfind(field + ":", 0) == 0) return std::stoull(line.substr(field.size() + 1)) * 1024ull;
  return std::nullopt;
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

std::optional<uint64_t> resident_bytes() { return status_field("VmRSS"); }
std::optional<uint64_t> peak_resident_bytes() { return status_field("VmHWM"); }

bool exceeds_memory_limit(uint64_t bytes) {
  const std::optional<uint64_t> limit = memory_limit_bytes();
  return limit && bytes > *limit / 10 * 9;
}

std::string format_bytes(uint64_t bytes) {
  char b[32];
  if (bytes >= (1ull << 30)) std::snprintf(b, sizeof b, "%.1f GB", bytes / double(1ull << 30));
  else std::snprintf(b, sizeof b, "%.0f MB", bytes / double(1ull << 20));
  return b;
}

}  // namespace tessera
