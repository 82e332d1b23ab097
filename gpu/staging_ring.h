// Host-to-device uploads for frames in flight: one host-visible staging buffer per frame slot,
// filled linearly, with the copies into device-local buffers recorded in the frame's batch. A
// slot is reused only once the GPU has finished the frame that last used it, so the CPU can
// write frame n+1's data while frame n still runs (Granite's and niagara's per-frame rings).
//
// Usage per frame: beginFrame(); upload(batch, ...) as often as needed; endFrame(submission of
// the batch). beginFrame() blocks (counted by Context::hostWaitCount) only when the caller runs
// more frames ahead than framesInFlight.
//
// Thread safety: as for the Context.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include <vulkan/vulkan.h>

#include "gpu/buffer.h"

namespace sdfstream::gpu {

class CommandBatch;
class Context;

class StagingRing {
 public:
  StagingRing(Context& context, std::uint32_t framesInFlight, std::size_t initialBytes = 1 << 16);
  StagingRing(const StagingRing&) = delete;
  StagingRing& operator=(const StagingRing&) = delete;

  void beginFrame();
  // Copies `bytes` into the current slot and records their copy to dst+dstOffset in `batch`.
  void upload(CommandBatch& batch, Buffer& dst, std::size_t dstOffset, const void* data,
              std::size_t bytes);
  template <typename T>
  void upload(CommandBatch& batch, Buffer& dst, std::span<const T> data, std::size_t dstOffset = 0) {
    upload(batch, dst, dstOffset, data.data(), data.size_bytes());
  }
  // Space for `bytes` in the current slot, to be filled by the caller and copied with
  // copyRegions (scattered uploads: one command for many ranges). Valid until the next
  // reserve()/upload() of this frame; returns the buffer and the offset in it.
  struct Reservation {
    const Buffer* buffer;
    std::size_t offset;
    std::uint8_t* data;
  };
  Reservation reserve(std::size_t bytes);
  void endFrame(std::uint64_t submission);

  std::uint32_t framesInFlight() const { return std::uint32_t(slots_.size()); }
  std::uint32_t currentSlot() const { return current_; }
  std::size_t bytesThisFrame() const { return bytesThisFrame_; }
  // Bytes of host-visible staging memory held by all slots.
  std::size_t capacityBytes() const;

 private:
  struct Slot {
    Buffer buffer;
    std::size_t used = 0;
    std::uint64_t submission = 0;  // the last frame that read it; 0 = never used
  };
  Context& context_;
  std::vector<Slot> slots_;
  std::uint32_t current_ = 0;
  std::uint64_t frames_ = 0;
  std::size_t bytesThisFrame_ = 0;
  bool inFrame_ = false;
};

}  // namespace sdfstream::gpu
