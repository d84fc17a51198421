// A test hook for the farm's liveness (tests/farm/farm_liveness_test.cpp):
// TESSERA_TEST_STOP=RANK:POINT[:N] makes rank RANK stop itself (SIGSTOP) the
// N-th time (default: the first) it reaches POINT, as a hung or suspended
// process would: "pass" (the master, as a pass begins), "tiles" (a worker,
// before it renders a batch of tiles), "result" (a worker, after it sent
// one back), "round" (a worker, before it sends a round of learning) or
// "bye" (a worker, after it answered the master's stop, before MPI_Finalize). It
// prints its pid first, so that a test can send it SIGCONT.
#pragma once

#include <cstdint>
#include <functional>

namespace tessera {

// The hook for this rank: empty unless TESSERA_TEST_STOP names it.
std::function<void(const char*)> farm_test_stop(int32_t rank);

}  // namespace tessera
