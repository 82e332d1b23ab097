// What the driver says a compiled compute pipeline costs (VK_KHR_pipeline_executable_properties):
// register count, shared and local (spill) memory, instruction counts -- whatever statistics the
// driver reports, by the driver's own names. It is the "compiler's resource report" to read
// before guessing why a pass runs below its floor: registers decide how many warps an SM keeps
// in flight, and spills add memory traffic no byte count predicts.
//
// Opt-in diagnostic: SDFSTREAM_PIPELINE_STATS=1 makes a Context that creates its own device
// enable the extension where the device has it; every ComputePipeline then prints one line
// "pipeline stats <shader>: <name>=<value>, ..." to stderr after it is created. An adopted
// (engine) device is left as the engine made it.
#pragma once

#include <string>

#include <vulkan/vulkan.h>

namespace sdfstream::gpu {

// The device extension the statistics need.
inline constexpr const char* kPipelineStatisticsExtension =
    VK_KHR_PIPELINE_EXECUTABLE_PROPERTIES_EXTENSION_NAME;

// One line describing every executable of `pipeline` (created with
// VK_PIPELINE_CREATE_CAPTURE_STATISTICS_BIT_KHR on a device with the extension enabled):
// "<executable name>: <statistic>=<value>, ..."; executables joined by "; ". Returns the reason
// instead when the driver reports nothing or a query fails.
std::string pipelineStatisticsLine(VkDevice device, VkPipeline pipeline);

}  // namespace sdfstream::gpu
