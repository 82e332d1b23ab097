// A storage buffer with its own memory allocation. Move-only RAII owner; destruction is deferred
// until the GPU has finished the last submission made before it (Context::deferDestroy).
//
// Memory cost: one vkAllocateMemory per buffer (drivers allow >= 4096 allocations), so make a
// few large buffers and sub-allocate (e.g. one brick atlas), not one buffer per brick.
// Thread safety: as for the Context (one thread at a time).
#pragma once

#include <cstddef>
#include <cstdint>

#include <vulkan/vulkan.h>

namespace sdfstream::gpu {

class Context;

enum class BufferKind {
  DeviceLocal,  // GPU memory (VRAM on discrete GPUs); upload/download go through a staging copy
  Upload,       // host-visible, coherent, uncached preferred: the CPU writes, the GPU reads
  Readback,     // host-visible, coherent, cached preferred: the GPU writes, the CPU reads
};

class Buffer {
 public:
  Buffer() = default;  // empty: no Vulkan object; only assignment and destruction are valid
  // `bytes` is rounded up to a multiple of 4 (minimum 4), so zero-size requests are valid and
  // vkCmdFillBuffer can cover the whole buffer. Every kind is usable as a storage buffer and as
  // a transfer source and destination. Contents start undefined. Throws std::runtime_error when
  // no memory type fits or allocation fails.
  Buffer(Context& ctx, std::size_t bytes, BufferKind kind);
  ~Buffer();
  Buffer(Buffer&& other) noexcept;
  Buffer& operator=(Buffer&& other) noexcept;
  Buffer(const Buffer&) = delete;
  Buffer& operator=(const Buffer&) = delete;

  // Copy `bytes` bytes between host memory and [offset, offset + bytes) of the buffer.
  // Precondition (checked, aborts): offset + bytes <= size().
  // Blocking and safe with respect to earlier GPU work: they wait for every submission made so
  // far, then copy (device-local: through a temporary staging buffer and a one-off submission).
  // For per-frame streaming write through mapped() with your own fencing instead.
  void upload(const void* data, std::size_t bytes, std::size_t offset = 0);
  void download(void* data, std::size_t bytes, std::size_t offset = 0) const;

  std::size_t size() const { return size_; }  // bytes, multiple of 4
  BufferKind kind() const { return kind_; }
  bool hostVisible() const { return mapped_ != nullptr; }
  // Persistently mapped, coherent pointer for Upload/Readback buffers; null for DeviceLocal.
  void* mapped() const { return mapped_; }
  VkBuffer handle() const { return buffer_; }
  explicit operator bool() const { return buffer_ != VK_NULL_HANDLE; }

 private:
  void release();

  Context* ctx_ = nullptr;
  VkBuffer buffer_ = VK_NULL_HANDLE;
  VkDeviceMemory memory_ = VK_NULL_HANDLE;
  void* mapped_ = nullptr;
  std::size_t size_ = 0;
  BufferKind kind_ = BufferKind::DeviceLocal;
};

}  // namespace sdfstream::gpu
