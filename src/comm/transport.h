// The farm's one communication layer: point-to-point messages between ranks
// and the one collective the farm needs (the setup broadcast). Everything
// after the setup is point-to-point with timeouts, so that no rank ever
// waits on a collective that a stalled rank would hold up (docs/farm.md). The master and workers speak only
// through it; MpiTransport (the only code that includes <mpi.h>) carries it
// over Open MPI, InProcessTransport over threads of one process (protocol
// tests without mpirun).
//
// Rank 0 is the master. Messages are byte strings with a tag; what they
// contain is comm/farm_protocol.h's business.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace tessera {

using Bytes = std::vector<uint8_t>;

struct Message {
  int32_t source = -1;
  int32_t tag = 0;
  Bytes bytes;
};

class Transport {
 public:
  virtual ~Transport() = default;
  virtual int32_t rank() const = 0;
  virtual int32_t size() const = 0;
  // Ranks sharing this rank's machine (to share its cores out).
  virtual int32_t ranks_on_this_machine() const { return 1; }
  // Machines the ranks run on (hosts; shared-memory nodes to MPI).
  virtual int32_t machines() const { return 1; }
  // Queues a message; never waits for the receiver (no deadlock when two
  // ranks send to each other at once).
  virtual void send(int32_t dest, int32_t tag, Bytes bytes) = 0;
  // The next message from `source` (any rank when -1), waiting without
  // spinning a core: ranks share machines with rendering threads.
  virtual Message receive(int32_t source = -1) = 0;
  // Like receive, but returns false at once when nothing has arrived.
  virtual bool try_receive(Message* out, int32_t source = -1) = 0;
  // Like receive, but returns false when nothing has arrived within `seconds`.
  virtual bool receive_within(Message* out, int32_t source, double seconds) = 0;
  // Root's bytes to every rank (others' input is replaced).
  virtual void broadcast(Bytes& bytes, int32_t root) = 0;
};

}  // namespace tessera
