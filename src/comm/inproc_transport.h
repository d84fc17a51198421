// A farm inside one process: each rank is a thread holding one endpoint of
// a shared hub. Runs the whole master/worker protocol in a unit test,
// without mpirun.
#pragma once

#include <condition_variable>
#include <deque>
#include <memory>
#include <mutex>

#include "comm/transport.h"

namespace tessera {

class InProcessHub {
 public:
  explicit InProcessHub(int32_t ranks);
  // The endpoint of one rank; the hub must outlive it.
  std::unique_ptr<Transport> endpoint(int32_t rank);

 private:
  friend class InProcessTransport;
  const int32_t ranks_;
  std::mutex mutex_;
  std::condition_variable changed_;
  std::vector<std::deque<Message>> inbox_;
  // The broadcast: ranks arrive, the last one publishes the result and
  // advances the generation the others wait on.
  int32_t arrived_ = 0;
  uint64_t generation_ = 0;
  Bytes broadcast_;
};

}  // namespace tessera
