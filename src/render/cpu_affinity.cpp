#include "render/cpu_affinity.h"

#include <sched.h>

#include <algorithm>
#include <thread>

namespace tessera {

int32_t usable_cores() {
  const int32_t machine = static_cast<int32_t>(std::max(1u, std::thread::hardware_concurrency()));
  cpu_set_t set;
  if (sched_getaffinity(0, sizeof set, &set) != 0) return machine;
  return std::max(1, std::min(machine, static_cast<int32_t>(CPU_COUNT(&set))));
}

bool widen_affinity_if_alone(int32_t ranks_on_this_machine) {
  const int32_t machine = static_cast<int32_t>(std::max(1u, std::thread::hardware_concurrency()));
  if (ranks_on_this_machine != 1 || usable_cores() >= machine) return false;
  cpu_set_t set;
  CPU_ZERO(&set);
  for (int32_t i = 0; i < machine && i < CPU_SETSIZE; ++i) CPU_SET(i, &set);
  return sched_setaffinity(0, sizeof set, &set) == 0;
}

}  // namespace tessera
