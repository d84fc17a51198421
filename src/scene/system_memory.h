// How much memory this process may still use, for refusing work that cannot
// fit before it starts (a film, a scene's arrays, a mesh being read).
#pragma once

#include <cstdint>
#include <optional>
#include <string>

namespace tessera {

// Memory free now: the smaller of the system's available memory
// (/proc/meminfo MemAvailable) and what the address-space limit (ulimit -v)
// leaves; nullopt when neither can be read.
std::optional<uint64_t> available_memory_bytes();
// All the memory this process could have: physical memory plus swap, or what
// ulimit -v leaves if that is less.
std::optional<uint64_t> memory_limit_bytes();

// Whether `bytes` more cannot fit: beyond nine tenths of memory_limit_bytes
// (a tenth held back for everything else). False when the limit is unknown.
bool exceeds_memory_limit(uint64_t bytes);

// This process's resident memory now (VmRSS) and at its peak so far
// (VmHWM), from /proc/self/status; nullopt where it cannot be read.
std::optional<uint64_t> resident_bytes();
std::optional<uint64_t> peak_resident_bytes();

// "1.5 GB"
std::string format_bytes(uint64_t bytes);

}  // namespace tessera
