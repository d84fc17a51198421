// Ctrl-C or SIGTERM during a render: the first asks it to stop after the
// pass under way, so that the image so far, the stats and the checkpoint
// (when asked for) are written as at any other stop, with stop_reason
// "interrupted"; a second one exits at once. Interrupted before its first
// pass, a render writes nothing. Under mpirun the ranks receive SIGTERM from
// mpirun, which kills them odls_base_sigkill_timeout seconds later (Open MPI
// 4.1: 1 s by default; docs/farm.md); workers leave the stop to the master.
// (SIGUSR1, which mpirun forwards, was tried: handling it crashed ranks.)
#pragma once

namespace tessera {

void install_interrupt_handlers();
bool interrupt_requested();
// For tests: as if a first signal had arrived, and back.
void request_interrupt();
void clear_interrupt();

}  // namespace tessera
