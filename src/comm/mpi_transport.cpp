#include "comm/mpi_transport.h"

#include <mpi.h>

#include <chrono>
#include <climits>
#include <cstdio>
#include <cstdlib>
#include <list>
#include <stdexcept>
#include <string>
#include <thread>

namespace tessera {
namespace {

void check(int rc, const char* what) {
  if (rc != MPI_SUCCESS) throw std::runtime_error(std::string("MPI: ") + what + " failed");
}

// Between polls of an unfinished operation. Short against a tile (ms), long
// enough that a waiting rank costs no measurable CPU.
void pause_briefly() { std::this_thread::sleep_for(std::chrono::microseconds(50)); }

class MpiTransport : public Transport {
 public:
  MpiTransport() {
    MPI_Comm_rank(MPI_COMM_WORLD, &rank_);
    MPI_Comm_size(MPI_COMM_WORLD, &size_);
    MPI_Comm local;
    MPI_Comm_split_type(MPI_COMM_WORLD, MPI_COMM_TYPE_SHARED, rank_, MPI_INFO_NULL, &local);
    MPI_Comm_size(local, &local_size_);
    // One leader per machine: their count is the number of machines.
    int local_rank = 0, leader = 0;
    MPI_Comm_rank(local, &local_rank);
    leader = local_rank == 0 ? 1 : 0;
    MPI_Allreduce(&leader, &machines_, 1, MPI_INT, MPI_SUM, MPI_COMM_WORLD);
    MPI_Comm_free(&local);
  }
  ~MpiTransport() override {
    // Messages still in flight must leave before MPI_Finalize.
    for (auto& p : pending_) MPI_Wait(&p.request, MPI_STATUS_IGNORE);
  }

  int32_t rank() const override { return rank_; }
  int32_t size() const override { return size_; }
  int32_t ranks_on_this_machine() const override { return local_size_; }
  int32_t machines() const override { return machines_; }

  void send(int32_t dest, int32_t tag, Bytes bytes) override {
    if (bytes.size() > static_cast<size_t>(INT_MAX)) throw std::runtime_error("MPI: message larger than 2 GB");
    pending_.push_back(Pending{MPI_REQUEST_NULL, std::move(bytes)});
    Pending& p = pending_.back();
    check(MPI_Isend(p.bytes.data(), static_cast<int>(p.bytes.size()), MPI_BYTE, dest, tag, MPI_COMM_WORLD, &p.request),
          "MPI_Isend");
    progress_sends();
  }

  Message receive(int32_t source) override {
    Message m;
    while (!try_receive(&m, source)) pause_briefly();
    return m;
  }

  bool try_receive(Message* out, int32_t source) override {
    progress_sends();
    int flag = 0;
    MPI_Status st;
    check(MPI_Iprobe(source < 0 ? MPI_ANY_SOURCE : source, MPI_ANY_TAG, MPI_COMM_WORLD, &flag, &st), "MPI_Iprobe");
    if (!flag) return false;
    int count = 0;
    MPI_Get_count(&st, MPI_BYTE, &count);
    out->source = st.MPI_SOURCE;
    out->tag = st.MPI_TAG;
    out->bytes.resize(static_cast<size_t>(count));
    check(MPI_Recv(out->bytes.data(), count, MPI_BYTE, st.MPI_SOURCE, st.MPI_TAG, MPI_COMM_WORLD, MPI_STATUS_IGNORE),
          "MPI_Recv");
    return true;
  }

  bool receive_within(Message* out, int32_t source, double seconds) override {
    const auto until = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
    while (!try_receive(out, source)) {
      if (std::chrono::steady_clock::now() >= until) return false;
      pause_briefly();
    }
    return true;
  }

  void broadcast(Bytes& bytes, int32_t root) override {
    uint64_t n = bytes.size();
    MPI_Request r;
    check(MPI_Ibcast(&n, 1, MPI_UINT64_T, root, MPI_COMM_WORLD, &r), "MPI_Ibcast");
    wait(&r);
    if (n > static_cast<uint64_t>(INT_MAX)) throw std::runtime_error("MPI: broadcast larger than 2 GB");
    bytes.resize(n);
    check(MPI_Ibcast(bytes.data(), static_cast<int>(n), MPI_BYTE, root, MPI_COMM_WORLD, &r), "MPI_Ibcast");
    wait(&r);
  }

 private:
  struct Pending {
    MPI_Request request;
    Bytes bytes;
  };

  void progress_sends() {
    for (auto it = pending_.begin(); it != pending_.end();) {
      int done = 0;
      MPI_Test(&it->request, &done, MPI_STATUS_IGNORE);
      it = done ? pending_.erase(it) : std::next(it);
    }
  }

  // Polls a collective to completion; our own sends keep moving meanwhile.
  void wait(MPI_Request* r) {
    for (;;) {
      int done = 0;
      check(MPI_Test(r, &done, MPI_STATUS_IGNORE), "MPI_Test");
      if (done) return;
      progress_sends();
      pause_briefly();
    }
  }

  int rank_ = 0, size_ = 1, local_size_ = 1, machines_ = 1;
  std::list<Pending> pending_;
};

}  // namespace

bool launched_by_mpirun() {
  for (const char* v : {"OMPI_COMM_WORLD_SIZE", "PMIX_RANK", "PMI_SIZE"})
    if (std::getenv(v)) return true;
  return false;
}

MpiSession::MpiSession() {
  int provided = 0;
  if (MPI_Init_thread(nullptr, nullptr, MPI_THREAD_SERIALIZED, &provided) != MPI_SUCCESS)
    throw std::runtime_error("MPI_Init_thread failed");
  if (provided < MPI_THREAD_SERIALIZED) {
    MPI_Finalize();
    throw std::runtime_error("this MPI library cannot be called from several threads (MPI_THREAD_SERIALIZED)");
  }
}

MpiSession::~MpiSession() {
  MPI_Finalize();
  if (!watchdog_.joinable()) return;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    done_ = true;
  }
  finalized_.notify_all();
  watchdog_.join();
}

void MpiSession::end_within(double seconds, int code, std::string message) {
  watchdog_ = std::thread([this, seconds, code, message = std::move(message)] {
    std::unique_lock<std::mutex> lock(mutex_);
    if (finalized_.wait_for(lock, std::chrono::duration<double>(seconds), [&] { return done_; })) return;
    std::fprintf(stderr, "%s\n", message.c_str());
    std::fflush(stderr);
    // From this thread while the main one waits inside MPI: Open MPI's
    // abort only asks mpirun to end the job (tried under 4.1.4).
    MPI_Abort(MPI_COMM_WORLD, code);
    std::_Exit(code);
  });
}

std::unique_ptr<Transport> MpiSession::world() { return std::make_unique<MpiTransport>(); }

void MpiSession::abort(int code) {
  MPI_Abort(MPI_COMM_WORLD, code);
  std::exit(code);
}

}  // namespace tessera
