// A device-local buffer with a host-visible twin, for a pass whose inputs come from the host or
// whose outputs go back to it. The pass binds device(), which lives in VRAM like an engine's own
// G-buffer or ray list; the host copies are recorded into the pass's batch around it, so a
// timed pass measures its own memory traffic and not PCIe. A pass that binds a host-visible
// buffer instead reads every byte across the bus (about 50 GB/s against the H200's 4.8 TB/s).
//
//   StagedBuffer in(ctx, StagedBuffer::ToDevice), out(ctx, StagedBuffer::ToHost);
//   in.reserve(bytesIn); std::memcpy(in.host(), data, bytesIn);
//   out.reserve(bytesOut);
//   in.recordCopy(batch, bytesIn); batch.dispatch(..., {&in.device(), &out.device()}, ...);
//   out.recordCopy(batch, bytesOut); batch.submitAndWait(); read out.host()
#pragma once

#include <cstddef>

#include "gpu/buffer.h"
#include "gpu/command_batch.h"
#include "gpu/context.h"

namespace sdfstream::gpu {

class StagedBuffer {
 public:
  enum Direction { ToDevice, ToHost };
  StagedBuffer(Context& ctx, Direction direction) : ctx_(&ctx), direction_(direction) {}

  // Grows both buffers to at least `bytes` (contents are lost when they grow). The caller
  // makes sure no submitted batch still uses them (every batch is waited for before the next).
  void reserve(std::size_t bytes) {
    if (device_.size() >= bytes && device_) return;
    device_ = Buffer(*ctx_, bytes, BufferKind::DeviceLocal);
    host_ =
        Buffer(*ctx_, bytes, direction_ == ToDevice ? BufferKind::Upload : BufferKind::Readback);
  }
  // Host -> device (ToDevice) or device -> host (ToHost) of the first `bytes` bytes.
  void recordCopy(CommandBatch& batch, std::size_t bytes) {
    if (bytes == 0) return;
    if (direction_ == ToDevice)
      batch.copy(host_, device_, bytes);
    else
      batch.copy(device_, host_, bytes);
  }
  Buffer& device() { return device_; }
  const Buffer& device() const { return device_; }
  void* host() const { return host_.mapped(); }

 private:
  Context* ctx_;
  Direction direction_;
  Buffer device_, host_;
};

}  // namespace sdfstream::gpu
