#include "master/interrupt.h"

#include <unistd.h>

#include <atomic>
#include <csignal>

namespace tessera {
namespace {

// Set by the handler (on whichever thread takes the signal), read by the
// render loop: a lock-free atomic is safe for both.
std::atomic<int> g_signals{0};
static_assert(std::atomic<int>::is_always_lock_free);

extern "C" void on_interrupt(int sig) {
  if (g_signals.exchange(1) > 0) _exit(128 + sig);
  static const char msg[] =
      "\ntessera: interrupted: finishing this pass and writing the image so far (again to quit at once)\n";
  const ssize_t ignored = write(STDERR_FILENO, msg, sizeof msg - 1);
  (void)ignored;
}

}  // namespace

void install_interrupt_handlers() {
  struct sigaction sa {};
  sa.sa_handler = on_interrupt;
  sigemptyset(&sa.sa_mask);
  sa.sa_flags = SA_RESTART;
  sigaction(SIGINT, &sa, nullptr);
  sigaction(SIGTERM, &sa, nullptr);
}

bool interrupt_requested() { return g_signals.load() > 0; }
void request_interrupt() { g_signals = 1; }
void clear_interrupt() { g_signals = 0; }

}  // namespace tessera
