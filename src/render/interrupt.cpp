#include "render/interrupt.h"

#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <csignal>

namespace tessera {
namespace {

// Set by the handler (on whichever thread takes the signal), read by the
// render loop: a lock-free atomic is safe for both.
std::atomic<int> g_signals{0};
// A stop asked for without a signal of the user's: mpirun's SIGCONT, or a
// worker's report. It never makes a later signal the second one.
std::atomic<bool> g_stop_asked{false};
static_assert(std::atomic<int>::is_always_lock_free);
std::atomic<bool> g_announce{true};

void say_interrupted() {
  if (!g_announce.load()) return;
  static const char msg[] =
      "\ntessera: interrupted: finishing this pass and writing the image so far (again to quit at once)\n";
  const int saved = errno;  // the interrupted code may be reading errno
  const ssize_t ignored = write(STDERR_FILENO, msg, sizeof msg - 1);
  (void)ignored;
  errno = saved;
}

extern "C" void on_interrupt(int sig) {
  if (g_signals.exchange(1) > 0) _exit(128 + sig);
  say_interrupted();
}

// mpirun's SIGCONT, the start of its kill sequence: sent by the rank's parent
// (mpirun, or the orted that started it) with kill(). A SIGCONT from anyone
// else (a scheduler resuming a suspended job, a debugger) is not a stop.
extern "C" void on_mpirun_continue(int, siginfo_t* info, void*) {
  if (info == nullptr || info->si_code != SI_USER || info->si_pid != getppid()) return;
  if (!g_stop_asked.exchange(true) && g_signals.load() == 0) say_interrupted();
}

}  // namespace

void install_interrupt_handlers(bool open_mpi, bool announce) {
  g_announce.store(announce);
  struct sigaction sa {};
  sa.sa_handler = on_interrupt;
  sigemptyset(&sa.sa_mask);
  sa.sa_flags = SA_RESTART;
  sigaction(SIGINT, &sa, nullptr);
  sigaction(SIGTERM, &sa, nullptr);
  if (open_mpi) {
    struct sigaction cont {};
    cont.sa_sigaction = on_mpirun_continue;
    sigemptyset(&cont.sa_mask);
    cont.sa_flags = SA_RESTART | SA_SIGINFO;
    sigaction(SIGCONT, &cont, nullptr);
  }
}

bool interrupt_requested() { return g_signals.load() > 0 || g_stop_asked.load(); }
void note_worker_interrupt() { g_stop_asked = true; }
void request_interrupt() { g_signals = 1; }
void clear_interrupt() {
  g_signals = 0;
  g_stop_asked = false;
}

}  // namespace tessera
