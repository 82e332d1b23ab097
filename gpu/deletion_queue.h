// Deferred destruction (STYLE.md habit 5): a GPU object may still be read by submitted work when
// its owner goes away (streaming evicts bricks the GPU is tracing). Owners therefore hand a
// destroy callback to the Context, tagged with the index of the last submission; it runs once the
// timeline semaphore has reached that index. This class is the bookkeeping only (no Vulkan), so
// it can be tested without a device.
//
// Thread safety: none; the owning Context is externally synchronized.
#pragma once

#include <cstddef>
#include <cstdint>
#include <deque>
#include <functional>

namespace sdfstream::gpu {

class DeletionQueue {
 public:
  DeletionQueue() = default;
  DeletionQueue(const DeletionQueue&) = delete;
  DeletionQueue& operator=(const DeletionQueue&) = delete;
  // Anything still queued is run: the owner must have waited for the GPU first.
  ~DeletionQueue() { runAll(); }

  // Queues `destroy` to run once submission `submission` has completed. Submission indices given
  // to push() never decrease, so the queue stays sorted and collect() only looks at the front.
  void push(std::uint64_t submission, std::function<void()> destroy);

  // Runs, in push order, every callback whose submission is <= `completed`. Returns how many ran.
  std::size_t collect(std::uint64_t completed);

  // Runs everything (after a full GPU wait).
  void runAll();

  std::size_t size() const { return entries_.size(); }

 private:
  struct Entry {
    std::uint64_t submission;
    std::function<void()> destroy;
  };
  std::deque<Entry> entries_;
};

}  // namespace sdfstream::gpu
