#include "gpu/staging_ring.h"

#include <algorithm>
#include <cstring>

#include "gpu/check.h"
#include "gpu/command_batch.h"
#include "gpu/context.h"

namespace sdfstream::gpu {
namespace {
// Copy offsets aligned so every upload may be read as uint/vec4 data by later passes.
constexpr std::size_t kAlign = 16;
std::size_t alignUp(std::size_t v) { return (v + kAlign - 1) / kAlign * kAlign; }
}  // namespace

StagingRing::StagingRing(Context& context, std::uint32_t framesInFlight, std::size_t initialBytes)
    : context_(context) {
  SDFSTREAM_GPU_CHECK(framesInFlight >= 1, "StagingRing needs at least one frame in flight");
  slots_.resize(framesInFlight);
  for (Slot& s : slots_) s.buffer = Buffer(context, std::max<std::size_t>(initialBytes, kAlign), BufferKind::Upload);
}

void StagingRing::beginFrame() {
  SDFSTREAM_GPU_CHECK(!inFrame_, "StagingRing::beginFrame twice without endFrame");
  current_ = std::uint32_t(frames_ % slots_.size());
  Slot& slot = slots_[current_];
  if (slot.submission != 0 && context_.completedSubmission() < slot.submission)
    context_.wait(slot.submission);  // more frames ahead than slots: back-pressure
  slot.used = 0;
  bytesThisFrame_ = 0;
  inFrame_ = true;
}

StagingRing::Reservation StagingRing::reserve(std::size_t bytes) {
  SDFSTREAM_GPU_CHECK(inFrame_, "StagingRing::reserve outside beginFrame/endFrame");
  Slot& slot = slots_[current_];
  const std::size_t offset = alignUp(slot.used);
  if (offset + bytes > slot.buffer.size()) {
    // The old buffer still holds this frame's earlier uploads, already recorded: its destruction
    // is deferred past the batch being recorded (Context::deferDestroy).
    const std::size_t grown = std::max(2 * slot.buffer.size(), alignUp(bytes) * 2);
    slot.buffer = Buffer(context_, grown, BufferKind::Upload);
    slot.used = 0;
    return reserve(bytes);
  }
  slot.used = offset + bytes;
  bytesThisFrame_ += bytes;
  return {&slot.buffer, offset, static_cast<std::uint8_t*>(slot.buffer.mapped()) + offset};
}

void StagingRing::upload(CommandBatch& batch, Buffer& dst, std::size_t dstOffset, const void* data,
                         std::size_t bytes) {
  if (bytes == 0) return;
  const Reservation r = reserve(bytes);
  std::memcpy(r.data, data, bytes);
  batch.copy(*r.buffer, dst, bytes, r.offset, dstOffset);
}

void StagingRing::endFrame(std::uint64_t submission) {
  SDFSTREAM_GPU_CHECK(inFrame_, "StagingRing::endFrame without beginFrame");
  slots_[current_].submission = submission;
  ++frames_;
  inFrame_ = false;
}

std::size_t StagingRing::capacityBytes() const {
  std::size_t total = 0;
  for (const Slot& s : slots_) total += s.buffer.size();
  return total;
}

}  // namespace sdfstream::gpu
