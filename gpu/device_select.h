// Choosing a physical device, kept apart from Vulkan calls so the rules can be tested on any
// machine (one job: a list of candidates in, an index or a one-line error out).
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include <vulkan/vulkan.h>

namespace sdfstream::gpu {

struct DeviceCandidate {
  std::string name;  // VkPhysicalDeviceProperties::deviceName
  VkPhysicalDeviceType type = VK_PHYSICAL_DEVICE_TYPE_OTHER;
  std::string unsuitableReason;  // empty = meets sdfstream's requirements
};

// Returns the index (into `candidates`) to use.
//  - `request` empty: the best suitable device, discrete > integrated > virtual > CPU > other,
//    ties broken by enumeration order.
//  - `request` all digits: that enumeration index.
//  - otherwise: the first device whose name contains `request`, case-insensitively.
// `requestSource` names where the request came from for messages ("--device",
// "SDFSTREAM_DEVICE"). Throws std::runtime_error with a one-line message listing the available
// devices when nothing matches, or when the match (or every device, for auto) is unsuitable.
std::size_t selectDevice(const std::vector<DeviceCandidate>& candidates, const std::string& request,
                         const std::string& requestSource = "--device");

// "discrete", "integrated", "virtual", "cpu", "other".
const char* deviceTypeName(VkPhysicalDeviceType type);

}  // namespace sdfstream::gpu
