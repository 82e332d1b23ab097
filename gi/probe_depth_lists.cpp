#include "gi/probe_depth_lists.h"

#include <cmath>

#include <glm/gtc/type_ptr.hpp>

#include "gi/probe_math.h"
#include "shaders/shared/probe_layout.h"

namespace sdfstream::probe {

void appendDepthRayLists(const glm::mat3& rotation, std::uint32_t rays, float sharpness,
                         std::vector<glm::vec4>& out) {
  using namespace gpu_shared;
  std::vector<glm::vec3> directions(rays);
  for (std::uint32_t r = 0; r < rays; ++r) directions[r] = rayDirection(r, rays, rotation);
  const std::size_t first = out.size();
  out.resize(first + std::size_t(kProbeDepthInterior) * kProbeDepthInterior * kProbeDepthListVec4s,
             glm::vec4(0.0f));
  for (std::uint32_t t = 0; t < kProbeDepthInterior * kProbeDepthInterior; ++t) {
    const glm::vec3 texelDir = texelDirection(
        glm::uvec2(t % kProbeDepthInterior, t / kProbeDepthInterior), kProbeDepthInterior);
    // The floor is relative to the texel's nearest ray: where no ray comes near (few rays, sharp
    // weights), the rays that do count are still all listed.
    std::uint32_t nearest = 0;
    for (std::uint32_t r = 1; r < rays; ++r)
      if (glm::dot(texelDir, directions[r]) > glm::dot(texelDir, directions[nearest])) nearest = r;
    const float nearestCos = rays > 0 ? glm::dot(texelDir, directions[nearest]) : 0.0f;
    // cos^s >= floor * nearest^s  <=>  cos >= floor^(1/s) * nearest: only rays inside that cone
    // pay for the pow.
    const float minCos =
        sharpness > 0.0f ? std::pow(kProbeDepthListFloor, 1.0f / sharpness) * nearestCos : 0.0f;
    const float minWeight =
        kProbeDepthListFloor *
        (rays > 0 ? depthWeight(texelDir, directions[nearest], sharpness) : 0.0f);
    float* block = glm::value_ptr(out[first + std::size_t(t) * kProbeDepthListVec4s]);
    std::uint32_t count = 0;
    for (std::uint32_t r = 0; r < rays && count <= kProbeDepthListRays; ++r) {
      if (glm::dot(texelDir, directions[r]) < minCos) continue;
      const float w = depthWeight(texelDir, directions[r], sharpness);
      if (w < minWeight || w <= 0.0f) continue;
      if (count < kProbeDepthListRays) {
        block[4 + 2 * count] = glm::uintBitsToFloat(r);
        block[4 + 2 * count + 1] = w;
      }
      ++count;
    }
    block[0] = glm::uintBitsToFloat(count > kProbeDepthListRays ? kProbeDepthListDense : count);
  }
}

}  // namespace sdfstream::probe
