// Which cores this process may run on. mpirun binds each rank to one core
// by default when it starts one or two ranks per machine: a rank alone on a
// machine would then render with one thread while the other cores idle.
#pragma once

#include <cstdint>

namespace tessera {

// Cores in this process's affinity mask (the machine's count where unknown).
int32_t usable_cores();

// When this is the only rank on its machine and it was bound to fewer cores
// than the machine has, lets it run on all of them. Returns true when it did.
bool widen_affinity_if_alone(int32_t ranks_on_this_machine);

}  // namespace tessera
