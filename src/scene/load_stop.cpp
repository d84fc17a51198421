#include "scene/load_stop.h"

#include <atomic>

namespace tessera {
namespace {

std::atomic<LoadStopCheck> g_check{nullptr};

}  // namespace

void set_load_stop_check(LoadStopCheck check) { g_check.store(check); }

bool load_stop_requested() {
  const LoadStopCheck check = g_check.load(std::memory_order_relaxed);
  return check && check();
}

void check_load_stop() {
  if (load_stop_requested()) throw LoadInterrupted("interrupted while loading the scene; nothing was rendered or written");
}

}  // namespace tessera
