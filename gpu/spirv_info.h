// The little SPIR-V reflection the gpu module needs: a compute shader's workgroup size, so a
// PipelineDesc that disagrees with the shader is caught at pipeline creation instead of giving
// silently wrong group counts (STYLE.md habit 3).
#pragma once

#include <cstdint>
#include <optional>
#include <span>

#include <glm/vec3.hpp>

namespace sdfstream::gpu {

// The LocalSize execution mode (local_size_x/y/z literals; the default values when the shader
// uses specialization constants). nullopt if the module is not SPIR-V or declares none (e.g. it
// uses LocalSizeId). Safe on untrusted words: never reads outside `words`.
std::optional<glm::uvec3> spirvLocalSize(std::span<const std::uint32_t> words);

}  // namespace sdfstream::gpu
