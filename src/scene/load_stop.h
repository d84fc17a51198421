// Stopping a scene load from outside (Ctrl-C or SIGTERM while a large scene
// loads): the application names what to ask (render/interrupt.h's
// interrupt_requested; scene/ cannot include render/), and the loader asks
// between directives and in its long loops, throwing LoadInterrupted, so a
// load stops within a fraction of a second instead of running to its end.
#pragma once

#include <stdexcept>

namespace tessera {

struct LoadInterrupted : std::runtime_error {
  using std::runtime_error::runtime_error;
};

using LoadStopCheck = bool (*)();
// null: never stop (the default: tests and tools that do not install handlers).
void set_load_stop_check(LoadStopCheck check);
bool load_stop_requested();
// Throws LoadInterrupted when a stop was requested.
void check_load_stop();

}  // namespace tessera
