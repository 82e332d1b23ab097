// Memory type selection, apart from Vulkan calls so it can be tested with made-up tables.
#pragma once

#include <cstdint>
#include <optional>

#include <vulkan/vulkan.h>

namespace sdfstream::gpu {

struct MemoryRequest {
  VkMemoryPropertyFlags required = 0;   // all of these, or the type is not eligible
  VkMemoryPropertyFlags preferred = 0;  // +1 per bit present
  VkMemoryPropertyFlags avoided = 0;    // -1 per bit present (e.g. HOST_VISIBLE for VRAM-only
                                        // buffers, to keep the small BAR heap free)
};

// The eligible memory type (allowed by `typeBits`, a VkMemoryRequirements::memoryTypeBits) with
// the best score; ties go to the lowest index, which the spec orders by driver preference.
// nullopt when no type is eligible.
std::optional<std::uint32_t> findMemoryType(const VkPhysicalDeviceMemoryProperties& properties,
                                            std::uint32_t typeBits, const MemoryRequest& request);

}  // namespace sdfstream::gpu
