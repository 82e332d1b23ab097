#include "gpu/spirv_info.h"

namespace sdfstream::gpu {

std::optional<glm::uvec3> spirvLocalSize(std::span<const std::uint32_t> words) {
  constexpr std::uint32_t kMagic = 0x07230203u;
  constexpr std::uint32_t kOpExecutionMode = 16;
  constexpr std::uint32_t kExecutionModeLocalSize = 17;
  constexpr std::size_t kHeaderWords = 5;
  if (words.size() < kHeaderWords || words[0] != kMagic) return std::nullopt;
  for (std::size_t i = kHeaderWords; i < words.size();) {
    const std::uint32_t count = words[i] >> 16, opcode = words[i] & 0xffffu;
    if (count == 0 || count > words.size() - i) return std::nullopt;  // malformed
    // OpExecutionMode <entry> LocalSize x y z
    if (opcode == kOpExecutionMode && count == 6 && words[i + 2] == kExecutionModeLocalSize)
      return glm::uvec3(words[i + 3], words[i + 4], words[i + 5]);
    i += count;
  }
  return std::nullopt;
}

}  // namespace sdfstream::gpu
