#include "gpu/deletion_queue.h"

#include "gpu/check.h"

namespace sdfstream::gpu {

void DeletionQueue::push(std::uint64_t submission, std::function<void()> destroy) {
  SDFSTREAM_GPU_CHECK(entries_.empty() || entries_.back().submission <= submission,
                      "deferred destructions must be queued in submission order");
  entries_.push_back({submission, std::move(destroy)});
}

std::size_t DeletionQueue::collect(std::uint64_t completed) {
  std::size_t ran = 0;
  while (!entries_.empty() && entries_.front().submission <= completed) {
    // Pop before running so a callback that throws cannot run twice.
    auto destroy = std::move(entries_.front().destroy);
    entries_.pop_front();
    destroy();
    ++ran;
  }
  return ran;
}

void DeletionQueue::runAll() {
  while (!entries_.empty()) {
    auto destroy = std::move(entries_.front().destroy);
    entries_.pop_front();
    destroy();
  }
}

}  // namespace sdfstream::gpu
