#include "gpu/device_select.h"

#include <algorithm>
#include <cctype>
#include <stdexcept>

namespace sdfstream::gpu {
namespace {

int typeRank(VkPhysicalDeviceType type) {
  switch (type) {
    case VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU:
      return 0;
    case VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU:
      return 1;
    case VK_PHYSICAL_DEVICE_TYPE_VIRTUAL_GPU:
      return 2;
    case VK_PHYSICAL_DEVICE_TYPE_CPU:
      return 3;
    default:
      return 4;
  }
}

std::string lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return s;
}

std::string describe(const std::vector<DeviceCandidate>& candidates) {
  if (candidates.empty()) return "none";
  std::string out;
  for (std::size_t i = 0; i < candidates.size(); ++i) {
    if (i) out += ", ";
    out += std::to_string(i) + ": " + candidates[i].name + " [" +
           deviceTypeName(candidates[i].type) + "]";
  }
  return out;
}

std::size_t checkSuitable(const std::vector<DeviceCandidate>& candidates, std::size_t index) {
  const DeviceCandidate& c = candidates[index];
  if (!c.unsuitableReason.empty())
    throw std::runtime_error("Vulkan device '" + c.name +
                             "' cannot run sdfstream: " + c.unsuitableReason);
  return index;
}

}  // namespace

const char* deviceTypeName(VkPhysicalDeviceType type) {
  switch (type) {
    case VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU:
      return "discrete";
    case VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU:
      return "integrated";
    case VK_PHYSICAL_DEVICE_TYPE_VIRTUAL_GPU:
      return "virtual";
    case VK_PHYSICAL_DEVICE_TYPE_CPU:
      return "cpu";
    default:
      return "other";
  }
}

std::size_t selectDevice(const std::vector<DeviceCandidate>& candidates, const std::string& request,
                         const std::string& requestSource) {
  if (request.empty()) {
    std::size_t best = candidates.size();
    for (std::size_t i = 0; i < candidates.size(); ++i) {
      if (!candidates[i].unsuitableReason.empty()) continue;
      if (best == candidates.size() ||
          typeRank(candidates[i].type) < typeRank(candidates[best].type))
        best = i;
    }
    if (best == candidates.size()) {
      std::string reasons;
      for (const auto& c : candidates) reasons += "; " + c.name + ": " + c.unsuitableReason;
      throw std::runtime_error("no suitable Vulkan device (available: " + describe(candidates) +
                               ")" + reasons);
    }
    return best;
  }

  const bool isIndex = std::all_of(request.begin(), request.end(),
                                   [](unsigned char c) { return std::isdigit(c) != 0; });
  if (isIndex && request.size() < 10) {
    std::size_t index = std::stoul(request);
    if (index < candidates.size()) return checkSuitable(candidates, index);
  } else {
    const std::string needle = lower(request);
    for (std::size_t i = 0; i < candidates.size(); ++i)
      if (lower(candidates[i].name).find(needle) != std::string::npos)
        return checkSuitable(candidates, i);
  }
  throw std::runtime_error("no Vulkan device matches " + requestSource + " '" + request +
                           "' (available: " + describe(candidates) + ")");
}

}  // namespace sdfstream::gpu
