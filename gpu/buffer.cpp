#include "gpu/buffer.h"

#include <cstdlib>
#include <cstring>
#include <stdexcept>
#include <string>
#include <utility>

#include "gpu/check.h"
#include "gpu/command_batch.h"
#include "gpu/context.h"
#include "gpu/memory_type.h"

namespace sdfstream::gpu {
namespace {

std::uint32_t chooseMemoryType(const Context& ctx, std::uint32_t typeBits, BufferKind kind) {
  const auto& props = ctx.memoryProperties();
  constexpr VkMemoryPropertyFlags kHost =
      VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT;
  std::optional<std::uint32_t> type;
  switch (kind) {
    case BufferKind::DeviceLocal:
      // Avoid host-visible device memory: on discrete GPUs without resizable BAR it is a small
      // heap that Upload buffers may want. Any type will do if no device-local one fits.
      type = findMemoryType(
          props, typeBits,
          {VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT, 0, VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT});
      if (!type) type = findMemoryType(props, typeBits, {});
      break;
    case BufferKind::Upload:
      // Uncached (write-combined) is fastest for CPU writes the CPU never reads back.
      type = findMemoryType(props, typeBits, {kHost, 0, VK_MEMORY_PROPERTY_HOST_CACHED_BIT});
      break;
    case BufferKind::Readback:
      // Cached, or CPU reads of GPU results crawl.
      type = findMemoryType(props, typeBits, {kHost, VK_MEMORY_PROPERTY_HOST_CACHED_BIT, 0});
      break;
  }
  if (!type)
    throw std::runtime_error(
        "no Vulkan memory type fits a " +
        std::string(kind == BufferKind::DeviceLocal ? "device-local" : "host-visible coherent") +
        " buffer on " + ctx.deviceName());
  return *type;
}

}  // namespace

Buffer::Buffer(Context& ctx, std::size_t bytes, BufferKind kind)
    : ctx_(&ctx), size_(bytes == 0 ? 4 : (bytes + 3) & ~std::size_t(3)), kind_(kind) {
  VkBufferCreateInfo info{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
  info.size = size_;
  info.usage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT |
               VK_BUFFER_USAGE_TRANSFER_DST_BIT | VK_BUFFER_USAGE_INDIRECT_BUFFER_BIT;
  info.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
  VkDevice device = ctx.device();
  SDFSTREAM_VK(vkCreateBuffer(device, &info, nullptr, &buffer_));
  try {
    VkMemoryRequirements req;
    vkGetBufferMemoryRequirements(device, buffer_, &req);
    VkMemoryAllocateInfo alloc{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
    alloc.allocationSize = req.size;
    alloc.memoryTypeIndex = chooseMemoryType(ctx, req.memoryTypeBits, kind);
    static const double injectedMiB = [] {
      const char* v = std::getenv("SDFSTREAM_INJECT_DEVICE_MEMORY_MIB");
      return v && *v ? std::strtod(v, nullptr) : -1.0;
    }();
    const VkResult allocated =
        kind == BufferKind::DeviceLocal && injectedMiB >= 0.0 &&
                double(ctx.liveBufferBytes() + req.size) > injectedMiB * double(1 << 20)
            ? VK_ERROR_OUT_OF_DEVICE_MEMORY
            : vkAllocateMemory(device, &alloc, nullptr, &memory_);
    if (allocated == VK_ERROR_OUT_OF_DEVICE_MEMORY)
      throw OutOfDeviceMemory("no device memory left for a buffer of " +
                              std::to_string(req.size >> 20) + " MiB on " + ctx.deviceName());
    SDFSTREAM_VK(allocated);
    SDFSTREAM_VK(vkBindBufferMemory(device, buffer_, memory_, 0));
    if (kind != BufferKind::DeviceLocal)
      SDFSTREAM_VK(vkMapMemory(device, memory_, 0, VK_WHOLE_SIZE, 0, &mapped_));
    ctx.liveBufferBytes_ += size_;
  } catch (...) {
    // Nothing was submitted with this buffer yet, so immediate destruction is safe.
    if (memory_) vkFreeMemory(device, memory_, nullptr);
    vkDestroyBuffer(device, buffer_, nullptr);
    throw;
  }
}

Buffer::~Buffer() { release(); }

Buffer::Buffer(Buffer&& other) noexcept
    : ctx_(std::exchange(other.ctx_, nullptr)),
      buffer_(std::exchange(other.buffer_, VK_NULL_HANDLE)),
      memory_(std::exchange(other.memory_, VK_NULL_HANDLE)),
      mapped_(std::exchange(other.mapped_, nullptr)),
      size_(std::exchange(other.size_, 0)),
      kind_(other.kind_) {}

Buffer& Buffer::operator=(Buffer&& other) noexcept {
  if (this != &other) {
    release();
    ctx_ = std::exchange(other.ctx_, nullptr);
    buffer_ = std::exchange(other.buffer_, VK_NULL_HANDLE);
    memory_ = std::exchange(other.memory_, VK_NULL_HANDLE);
    mapped_ = std::exchange(other.mapped_, nullptr);
    size_ = std::exchange(other.size_, 0);
    kind_ = other.kind_;
  }
  return *this;
}

void Buffer::release() {
  if (!buffer_) return;
  ctx_->liveBufferBytes_ -= size_;
  // The GPU may still read this buffer in a submitted batch: free it after that batch.
  ctx_->deferDestroy([device = ctx_->device(), buffer = buffer_, memory = memory_] {
    vkDestroyBuffer(device, buffer, nullptr);
    vkFreeMemory(device, memory, nullptr);  // implicitly unmaps
  });
  buffer_ = VK_NULL_HANDLE;
  memory_ = VK_NULL_HANDLE;
  mapped_ = nullptr;
}

void Buffer::upload(const void* data, std::size_t bytes, std::size_t offset) {
  SDFSTREAM_GPU_CHECK(buffer_ && offset <= size_ && bytes <= size_ - offset,
                      "Buffer::upload out of range");
  if (bytes == 0) return;
  if (mapped_) {
    ctx_->waitIdle();  // earlier batches may still read the bytes we overwrite
    std::memcpy(static_cast<char*>(mapped_) + offset, data, bytes);
    return;
  }
  Buffer staging(*ctx_, bytes, BufferKind::Upload);
  std::memcpy(staging.mapped(), data, bytes);
  CommandBatch batch = ctx_->beginBatch(0);
  batch.copy(staging, *this, bytes, 0, offset);
  batch.submitAndWait();
}

void Buffer::download(void* data, std::size_t bytes, std::size_t offset) const {
  SDFSTREAM_GPU_CHECK(buffer_ && offset <= size_ && bytes <= size_ - offset,
                      "Buffer::download out of range");
  if (bytes == 0) return;
  if (mapped_) {
    ctx_->waitIdle();  // earlier batches may still write the bytes we read
    std::memcpy(data, static_cast<const char*>(mapped_) + offset, bytes);
    return;
  }
  Buffer staging(*ctx_, bytes, BufferKind::Readback);
  CommandBatch batch = ctx_->beginBatch(0);
  batch.copy(*this, staging, bytes, offset, 0);
  batch.submitAndWait();  // ends with a barrier making transfer writes visible to the host
  std::memcpy(data, staging.mapped(), bytes);
}

}  // namespace sdfstream::gpu
