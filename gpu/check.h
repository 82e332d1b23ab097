// Error tiers of the gpu module (STYLE.md habit 6):
//  - SDFSTREAM_GPU_CHECK: programmer errors (wrong push-constant size, out-of-range copy). Always
//    on, also in release builds; prints file, line and reason, then aborts.
//  - vkCheck: a Vulkan call failed at run time (out of memory, device lost). Throws
//    std::runtime_error naming the call and the VkResult; only thrown from set-up and blocking
//    calls (create, upload/download, submit), never from recording.
#pragma once

#include <string_view>

#include <vulkan/vulkan.h>

namespace sdfstream::gpu {

// "VK_ERROR_OUT_OF_DEVICE_MEMORY", or "VkResult(<n>)" for codes this table does not know.
const char* vkResultName(VkResult result);

namespace detail {
[[noreturn]] void checkFailed(const char* condition, std::string_view message, const char* file,
                              int line);
[[noreturn]] void vkFailed(VkResult result, const char* call, const char* file, int line);
}  // namespace detail

}  // namespace sdfstream::gpu

#define SDFSTREAM_GPU_CHECK(cond, message)                                                    \
  do {                                                                                        \
    if (!(cond)) ::sdfstream::gpu::detail::checkFailed(#cond, (message), __FILE__, __LINE__); \
  } while (0)

// Throws std::runtime_error("vkCreateBuffer failed: VK_ERROR_... (gpu/buffer.cpp:42)") unless
// the call returned VK_SUCCESS.
#define SDFSTREAM_VK(call)                                                                 \
  do {                                                                                     \
    VkResult sdfstream_vk_result_ = (call);                                                \
    if (sdfstream_vk_result_ != VK_SUCCESS)                                                \
      ::sdfstream::gpu::detail::vkFailed(sdfstream_vk_result_, #call, __FILE__, __LINE__); \
  } while (0)
