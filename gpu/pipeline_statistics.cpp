#include "gpu/pipeline_statistics.h"

#include <cstdio>
#include <vector>

namespace sdfstream::gpu {
namespace {

std::string valueText(const VkPipelineExecutableStatisticKHR& s) {
  char text[64];
  switch (s.format) {
    case VK_PIPELINE_EXECUTABLE_STATISTIC_FORMAT_BOOL32_KHR:
      return s.value.b32 ? "true" : "false";
    case VK_PIPELINE_EXECUTABLE_STATISTIC_FORMAT_INT64_KHR:
      std::snprintf(text, sizeof text, "%lld", static_cast<long long>(s.value.i64));
      return text;
    case VK_PIPELINE_EXECUTABLE_STATISTIC_FORMAT_UINT64_KHR:
      std::snprintf(text, sizeof text, "%llu", static_cast<unsigned long long>(s.value.u64));
      return text;
    case VK_PIPELINE_EXECUTABLE_STATISTIC_FORMAT_FLOAT64_KHR:
      std::snprintf(text, sizeof text, "%g", s.value.f64);
      return text;
    default:
      return "?";
  }
}

}  // namespace

std::string pipelineStatisticsLine(VkDevice device, VkPipeline pipeline) {
  // Extension entry points are not exported by the loader: fetch them from the device.
  auto getProperties = reinterpret_cast<PFN_vkGetPipelineExecutablePropertiesKHR>(
      vkGetDeviceProcAddr(device, "vkGetPipelineExecutablePropertiesKHR"));
  auto getStatistics = reinterpret_cast<PFN_vkGetPipelineExecutableStatisticsKHR>(
      vkGetDeviceProcAddr(device, "vkGetPipelineExecutableStatisticsKHR"));
  if (!getProperties || !getStatistics) return "the driver does not expose the statistics";

  VkPipelineInfoKHR info{VK_STRUCTURE_TYPE_PIPELINE_INFO_KHR};
  info.pipeline = pipeline;
  std::uint32_t count = 0;
  if (getProperties(device, &info, &count, nullptr) != VK_SUCCESS || count == 0)
    return "the driver reports no executables";
  std::vector<VkPipelineExecutablePropertiesKHR> executables(
      count, {VK_STRUCTURE_TYPE_PIPELINE_EXECUTABLE_PROPERTIES_KHR});
  if (getProperties(device, &info, &count, executables.data()) != VK_SUCCESS)
    return "vkGetPipelineExecutablePropertiesKHR failed";

  std::string line;
  for (std::uint32_t e = 0; e < count; ++e) {
    VkPipelineExecutableInfoKHR which{VK_STRUCTURE_TYPE_PIPELINE_EXECUTABLE_INFO_KHR};
    which.pipeline = pipeline;
    which.executableIndex = e;
    std::uint32_t n = 0;
    if (getStatistics(device, &which, &n, nullptr) != VK_SUCCESS) continue;
    std::vector<VkPipelineExecutableStatisticKHR> stats(
        n, {VK_STRUCTURE_TYPE_PIPELINE_EXECUTABLE_STATISTIC_KHR});
    if (getStatistics(device, &which, &n, stats.data()) != VK_SUCCESS) continue;
    if (!line.empty()) line += "; ";
    line += std::string(executables[e].name) + ":";
    for (std::uint32_t i = 0; i < n; ++i)
      line += std::string(i ? ", " : " ") + stats[i].name + "=" + valueText(stats[i]);
  }
  return line.empty() ? "the driver reports no statistics" : line;
}

}  // namespace sdfstream::gpu
