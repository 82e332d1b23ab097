#include "gpu/memory_type.h"

#include <bit>

namespace sdfstream::gpu {

std::optional<std::uint32_t> findMemoryType(const VkPhysicalDeviceMemoryProperties& properties,
                                            std::uint32_t typeBits, const MemoryRequest& request) {
  std::optional<std::uint32_t> best;
  int bestScore = 0;
  for (std::uint32_t i = 0; i < properties.memoryTypeCount; ++i) {
    if (!(typeBits & (1u << i))) continue;
    const VkMemoryPropertyFlags flags = properties.memoryTypes[i].propertyFlags;
    if ((flags & request.required) != request.required) continue;
    // Protected and lazily-allocated memory cannot back ordinary storage buffers usefully.
    if (flags & (VK_MEMORY_PROPERTY_PROTECTED_BIT | VK_MEMORY_PROPERTY_LAZILY_ALLOCATED_BIT))
      continue;
    const int score =
        std::popcount(flags & request.preferred) - std::popcount(flags & request.avoided);
    if (!best || score > bestScore) {
      best = i;
      bestScore = score;
    }
  }
  return best;
}

}  // namespace sdfstream::gpu
