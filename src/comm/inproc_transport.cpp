#include "comm/inproc_transport.h"

#include <chrono>
#include <stdexcept>

namespace tessera {

class InProcessTransport : public Transport {
 public:
  InProcessTransport(InProcessHub& hub, int32_t rank) : hub_(hub), rank_(rank) {}
  int32_t rank() const override { return rank_; }
  int32_t size() const override { return hub_.ranks_; }
  // Threads of one process share its cores.
  int32_t ranks_on_this_machine() const override { return hub_.ranks_; }

  void send(int32_t dest, int32_t tag, Bytes bytes) override {
    if (dest < 0 || dest >= hub_.ranks_) throw std::logic_error("send to a rank that does not exist");
    std::lock_guard<std::mutex> lock(hub_.mutex_);
    hub_.inbox_[dest].push_back(Message{rank_, tag, std::move(bytes)});
    hub_.changed_.notify_all();
  }

  Message receive(int32_t source) override {
    std::unique_lock<std::mutex> lock(hub_.mutex_);
    Message m;
    hub_.changed_.wait(lock, [&] { return take(source, &m); });
    return m;
  }

  bool try_receive(Message* out, int32_t source) override {
    std::lock_guard<std::mutex> lock(hub_.mutex_);
    return take(source, out);
  }

  bool receive_within(Message* out, int32_t source, double seconds) override {
    std::unique_lock<std::mutex> lock(hub_.mutex_);
    return hub_.changed_.wait_for(lock, std::chrono::duration<double>(seconds), [&] { return take(source, out); });
  }

  void broadcast(Bytes& bytes, int32_t root) override {
    std::unique_lock<std::mutex> lock(hub_.mutex_);
    if (rank_ == root) hub_.broadcast_ = bytes;
    collective_arrive(lock, [] {});
    bytes = hub_.broadcast_;
  }

 private:
  // Must be called with the lock held; messages from one source stay in order.
  bool take(int32_t source, Message* out) {
    auto& q = hub_.inbox_[rank_];
    for (auto it = q.begin(); it != q.end(); ++it) {
      if (source >= 0 && it->source != source) continue;
      *out = std::move(*it);
      q.erase(it);
      return true;
    }
    return false;
  }

  // Waits until every rank has arrived; the last one runs `publish` first.
  template <class Publish>
  void collective_arrive(std::unique_lock<std::mutex>& lock, Publish publish) {
    const uint64_t gen = hub_.generation_;
    if (++hub_.arrived_ == hub_.ranks_) {
      publish();
      hub_.arrived_ = 0;
      ++hub_.generation_;
      hub_.changed_.notify_all();
    } else {
      hub_.changed_.wait(lock, [&] { return hub_.generation_ != gen; });
    }
  }

  InProcessHub& hub_;
  int32_t rank_;
};

InProcessHub::InProcessHub(int32_t ranks) : ranks_(ranks), inbox_(static_cast<size_t>(ranks)) {}

std::unique_ptr<Transport> InProcessHub::endpoint(int32_t rank) {
  return std::make_unique<InProcessTransport>(*this, rank);
}

}  // namespace tessera
