// The depth blend's ray lists (shaders/shared/probe_layout.h, kProbeDepthList*): per depth
// interior texel of a probe's octahedral map, the rays of this frame's pattern whose power-cosine
// weight counts, with that weight. Every probe casts the same pattern (one rotation per frame),
// so the lists are built once per pattern on the host instead of per probe and texel on the GPU,
// where the blend spent most of its time on 128 pow() a texel, nearly all of them ~0.
#pragma once

#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

namespace sdfstream::probe {

// Appends the lists of the pattern `rotation` x Fibonacci(rays) at `sharpness` to `out`:
// kProbeDepthInterior² blocks of kProbeDepthListVec4s vec4 in the layout probe_layout.h states.
void appendDepthRayLists(const glm::mat3& rotation, std::uint32_t rays, float sharpness,
                         std::vector<glm::vec4>& out);

}  // namespace sdfstream::probe
