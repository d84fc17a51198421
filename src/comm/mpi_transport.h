// The farm over Open MPI. This file pair is the only code that includes
// <mpi.h>. Waits poll with short sleeps instead of Open MPI's busy polling:
// a rank waiting for the master must leave its core to the rendering
// threads beside it (Open MPI has no background progress here, see
// docs/farm.md).
#pragma once

#include <condition_variable>
#include <memory>
#include <mutex>
#include <string>
#include <thread>

#include "comm/transport.h"

namespace tessera {

// Whether this process was started by mpirun (so that `tessera render`
// alone never initialises MPI).
bool launched_by_mpirun();

// MPI_Init_thread / MPI_Finalize around a farm run. The master's rendering
// threads take turns answering workers (MPI_THREAD_SERIALIZED: one thread in
// MPI at a time, which the caller guarantees).
class MpiSession {
 public:
  MpiSession();
  ~MpiSession();
  MpiSession(const MpiSession&) = delete;
  MpiSession& operator=(const MpiSession&) = delete;
  std::unique_ptr<Transport> world();
  // Ends every rank of the job with this exit code (after an error on one).
  [[noreturn]] static void abort(int code);
  // Once the farm's work is done: unless this process is through
  // MPI_Finalize (which waits for every rank) within `seconds`, `message`
  // goes to stderr and the job ends with `code`. A rank stopped at the very
  // end would otherwise hold the job for ever. The countdown starts now.
  void end_within(double seconds, int code, std::string message);

 private:
  std::thread watchdog_;
  std::mutex mutex_;
  std::condition_variable finalized_;
  bool done_ = false;
};

}  // namespace tessera
