#include "render/ordered_splats.h"

#include <stdexcept>
#include <string>

namespace tessera {

OrderedSplats::OrderedSplats(Film& film, size_t jobs)
    : film_(film), waiting_(jobs), light_paths_(jobs, 0), ready_(jobs, 0) {}

void OrderedSplats::add(size_t index, std::vector<Splat>&& splats, uint64_t light_paths) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (index >= ready_.size() || ready_[index])
    throw std::runtime_error("light-path splats for tile " + std::to_string(index) + " arrived twice or out of range");
  waiting_[index] = std::move(splats);
  light_paths_[index] = light_paths;
  ready_[index] = 1;
  for (; next_ < ready_.size() && ready_[next_]; ++next_) {
    film_add_splats(film_, waiting_[next_], light_paths_[next_]);
    std::vector<Splat>().swap(waiting_[next_]);
  }
}

void OrderedSplats::finish() const {
  if (next_ != ready_.size())
    throw std::logic_error("light-path splats of " + std::to_string(ready_.size() - next_) + " tiles missing");
}

}  // namespace tessera
