// Ctrl-C and SIGTERM during a render: the first asks it to stop after the
// pass under way, so that the image so far, the stats and the checkpoint
// (when asked for) are written as at any other stop, with stop_reason
// "interrupted"; a second one exits at once. Farm workers install the same
// handlers, so that the signal mpirun passes on to every rank leaves the
// stop to the master.
#pragma once

namespace tessera {

void install_interrupt_handlers();
bool interrupt_requested();
// For tests: as if a first signal had arrived, and back.
void request_interrupt();
void clear_interrupt();

}  // namespace tessera
