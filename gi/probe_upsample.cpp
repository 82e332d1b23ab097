#include "gi/probe_upsample.h"

#include <tbb/parallel_for.h>

namespace sdfstream::probe {
namespace {
using namespace glm;
using gpu_shared::ProbeQuery;

// The GLSL becomes member functions reading this object's spans.
struct UpsamplePass {
  const ProbeQuery* queries = nullptr;
  const glm::vec4* low = nullptr;
#define PROBE_UPSAMPLE_QUERY(i) queries[i]
#define PROBE_UPSAMPLE_LOW(i) low[i]
#include "shaders/probe_upsample.glsl"
#undef PROBE_UPSAMPLE_QUERY
#undef PROBE_UPSAMPLE_LOW
};
}  // namespace

std::uint32_t halfResolutionInvocations(std::uint32_t lowWidth, std::uint32_t lowHeight) {
  return UpsamplePass{}.probeTiledInvocations(lowWidth, lowHeight);
}

float upsampleSimilarity(glm::vec3 p, glm::vec3 n, glm::vec3 pk, glm::vec3 nk) {
  return UpsamplePass{}.probeUpsampleSimilarity(p, n, pk, nk);
}

HalfResolutionPlan planHalfResolution(std::span<const ProbeQuery> image, std::uint32_t width,
                                      std::uint32_t height, std::uint32_t blockSize) {
  HalfResolutionPlan plan;
  plan.blockSize = blockSize;
  plan.lowWidth = (width + blockSize - 1) / blockSize;
  plan.lowHeight = (height + blockSize - 1) / blockSize;
  const std::uint32_t none = blockSize * blockSize;
  const std::uint32_t n = halfResolutionInvocations(plan.lowWidth, plan.lowHeight);
  plan.queries.assign(n, ProbeQuery{});
  plan.lowPixel.assign(n, ~0u);
  plan.sampledPixel.assign(n, none);
  UpsamplePass pass{image.data(), nullptr};
  for (std::uint32_t id = 0; id < n; ++id) {
    const glm::uvec2 block = pass.probeTiledPixel(id, plan.lowWidth);
    if (block.x >= plan.lowWidth || block.y >= plan.lowHeight) continue;
    plan.lowPixel[id] = block.x + plan.lowWidth * block.y;
    const std::uint32_t k = pass.probeBlockSampledPixel(block, blockSize, width, height);
    plan.sampledPixel[id] = k;
    if (k < none) {
      const glm::uvec2 p = block * blockSize + glm::uvec2(k % blockSize, k / blockSize);
      plan.queries[id] = image[p.x + std::size_t(width) * p.y];
    }
  }
  return plan;
}

std::vector<glm::vec4> halfResolutionSamples(const HalfResolutionPlan& plan,
                                             std::span<const glm::vec3> sampled) {
  const std::uint32_t none = plan.blockSize * plan.blockSize;
  std::vector<glm::vec4> low(std::size_t(plan.lowWidth) * plan.lowHeight, glm::vec4(0, 0, 0, -1));
  for (std::size_t id = 0; id < plan.lowPixel.size(); ++id)
    if (plan.lowPixel[id] != ~0u && plan.sampledPixel[id] < none)
      low[plan.lowPixel[id]] = glm::vec4(sampled[id], float(plan.sampledPixel[id]));
  return low;
}

std::vector<glm::vec3> upsampleHalfResolution(std::span<const ProbeQuery> image,
                                              std::span<const glm::vec4> low, std::uint32_t width,
                                              std::uint32_t height, std::uint32_t blockSize) {
  std::vector<glm::vec3> out(image.size());
  UpsamplePass pass{image.data(), low.data()};
  tbb::parallel_for(std::uint32_t(0), height, [&](std::uint32_t y) {
    for (std::uint32_t x = 0; x < width; ++x)
      out[x + std::size_t(width) * y] =
          pass.probeUpsampleBlockPixel(x, y, blockSize, width, height);
  });
  return out;
}

}  // namespace sdfstream::probe
