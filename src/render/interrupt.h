// Ctrl-C or SIGTERM during a render: the first asks it to stop after the
// pass under way, so that the image so far, the stats and the checkpoint
// (when asked for) are written as at any other stop, with stop_reason
// "interrupted"; a second one exits at once. Interrupted before its first
// pass, a render writes nothing.
//
// Under mpirun, Ctrl-C makes Open MPI 4.1 send every rank SIGCONT at once,
// SIGTERM odls_base_sigkill_timeout seconds later and SIGKILL as long again
// (docs/farm.md). So a rank started by Open MPI stops after the pass on a
// SIGCONT from its parent (mpirun or orted), without counting it as a
// signal: mpirun's SIGTERM is then the first, and the farm has twice the
// timeout to finish and write. A SIGCONT from anyone else (a scheduler
// resuming a suspended job) is not a stop. A signalled worker
// tells the master with its next tile request, and the master stops the
// farm the same way. (SIGUSR1, which mpirun forwards, was tried: handling it
// crashed ranks.)
#pragma once

namespace tessera {

// open_mpi: started by Open MPI's mpirun, whose SIGCONT asks for the stop
// (see above). announce: this process says on stderr that it is stopping
// (rank 0 only: every rank of a farm gets the signal).
void install_interrupt_handlers(bool open_mpi, bool announce = true);
// A first signal here, or a worker's (note_worker_interrupt).
bool interrupt_requested();
// A farm worker was signalled: stop after the pass, without counting as a
// signal here (the master's own first signal still lets it finish writing).
void note_worker_interrupt();
// For tests: as if a first signal had arrived, and back.
void request_interrupt();
void clear_interrupt();

}  // namespace tessera
