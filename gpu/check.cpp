#include "gpu/check.h"

#include <cstdio>
#include <cstdlib>
#include <stdexcept>
#include <string>

namespace sdfstream::gpu {

const char* vkResultName(VkResult result) {
  switch (result) {
#define SDF_CASE(x) \
  case x:           \
    return #x;
    SDF_CASE(VK_SUCCESS)
    SDF_CASE(VK_NOT_READY)
    SDF_CASE(VK_TIMEOUT)
    SDF_CASE(VK_INCOMPLETE)
    SDF_CASE(VK_ERROR_OUT_OF_HOST_MEMORY)
    SDF_CASE(VK_ERROR_OUT_OF_DEVICE_MEMORY)
    SDF_CASE(VK_ERROR_INITIALIZATION_FAILED)
    SDF_CASE(VK_ERROR_DEVICE_LOST)
    SDF_CASE(VK_ERROR_MEMORY_MAP_FAILED)
    SDF_CASE(VK_ERROR_LAYER_NOT_PRESENT)
    SDF_CASE(VK_ERROR_EXTENSION_NOT_PRESENT)
    SDF_CASE(VK_ERROR_FEATURE_NOT_PRESENT)
    SDF_CASE(VK_ERROR_INCOMPATIBLE_DRIVER)
    SDF_CASE(VK_ERROR_TOO_MANY_OBJECTS)
    SDF_CASE(VK_ERROR_FORMAT_NOT_SUPPORTED)
    SDF_CASE(VK_ERROR_UNKNOWN)
    SDF_CASE(VK_ERROR_OUT_OF_POOL_MEMORY)
    SDF_CASE(VK_ERROR_INVALID_SHADER_NV)
#undef SDF_CASE
    default:
      break;
  }
  thread_local std::string unknown;
  unknown = "VkResult(" + std::to_string(static_cast<int>(result)) + ")";
  return unknown.c_str();
}

namespace detail {

void checkFailed(const char* condition, std::string_view message, const char* file, int line) {
  std::fprintf(stderr, "%s:%d: gpu CHECK failed: %s: %.*s\n", file, line, condition,
               static_cast<int>(message.size()), message.data());
  std::fflush(stderr);
  std::abort();
}

void vkFailed(VkResult result, const char* call, const char* file, int line) {
  std::string name = call;
  if (auto paren = name.find('('); paren != std::string::npos) name.resize(paren);
  throw std::runtime_error(name + " failed: " + vkResultName(result) + " (" + file + ":" +
                           std::to_string(line) + ")");
}

}  // namespace detail
}  // namespace sdfstream::gpu
