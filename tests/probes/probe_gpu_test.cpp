// GPU == CPU for the probe math: shaders/probe_math_selftest.comp runs probe_math.glsl on the
// device; gi/probe_math.h runs the same file compiled as C++. Fixed seeds; stated tolerances
// cover only transcendental (sin/cos/pow) and division rounding differences.
#include <cmath>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "gi/probe_math.h"
#include "gpu/buffer.h"
#include "gpu/command_batch.h"
#include "gpu/compute_pipeline.h"
#include "tests/support/gpu_test.h"

namespace sdfstream::probe {
namespace {

struct SelftestPush {      // matches `Push` in shaders/probe_math_selftest.comp
  glm::vec4 rotationCol0;  // bytes 0..15
  glm::vec4 rotationCol1;  // 16..31
  glm::vec4 rotationCol2;  // 32..47
  glm::uvec4 counts;       // 48..63: x items, y rays per probe
};
static_assert(sizeof(SelftestPush) == 64);

class ProbeGpuTest : public test::GpuTest {};

TEST_F(ProbeGpuTest, SelftestShaderMatchesCpu) {
  constexpr std::uint32_t kItems = 4096 + 17;  // partial last workgroup
  constexpr std::uint32_t kRays = gpu_shared::kProbeDefaultRays;
  std::mt19937 rng(21u);
  std::normal_distribution<float> g;
  std::uniform_real_distribution<float> u(-1.0f, 1.0f), dist(0.0f, 12.0f);
  std::vector<glm::vec4> inputs(2 * kItems);
  for (std::uint32_t i = 0; i < kItems; ++i) {
    glm::vec3 d(g(rng), g(rng), g(rng));
    d = glm::length(d) > 1e-3f ? glm::normalize(d) : glm::vec3(0, 0, 1);
    inputs[2 * i] = glm::vec4(d, 0.0f);
    inputs[2 * i + 1] = glm::vec4(u(rng), u(rng), dist(rng), 0.0f);
  }
  const glm::mat3 rotation = randomRotation(77u);
  const SelftestPush push{glm::vec4(rotation[0], 0.0f), glm::vec4(rotation[1], 0.0f),
                          glm::vec4(rotation[2], 0.0f), glm::uvec4(kItems, kRays, 0, 0)};

  gpu::Buffer in(ctx(), inputs.size() * sizeof(glm::vec4), gpu::BufferKind::DeviceLocal);
  gpu::Buffer out(ctx(), 4 * kItems * sizeof(glm::vec4), gpu::BufferKind::DeviceLocal);
  in.upload(inputs.data(), inputs.size() * sizeof(glm::vec4));
  gpu::ComputePipeline pipeline(ctx(), gpu::ShaderId::probe_math_selftest,
                                {.storageBufferCount = 2,
                                 .pushConstantBytes = sizeof(SelftestPush),
                                 .workgroupSize = {64, 1, 1}});
  gpu::CommandBatch batch = ctx().beginBatch();
  batch.dispatch("probe_math_selftest", pipeline, {&in, &out}, &push, sizeof push, {kItems, 1, 1});
  batch.submitAndWait();
  std::vector<glm::vec4> gpu(4 * kItems);
  out.download(gpu.data(), gpu.size() * sizeof(glm::vec4));

  float worstDir = 0.0f, worstOct = 0.0f, worstTile = 0.0f, worstDecode = 0.0f, worstW = 0.0f;
  int borderMismatches = 0;
  for (std::uint32_t i = 0; i < kItems; ++i) {
    const glm::vec3 d(inputs[2 * i]);
    const glm::vec4 other = inputs[2 * i + 1];
    const glm::vec4* o = &gpu[4 * i];
    worstDir =
        std::max(worstDir, glm::length(glm::vec3(o[0]) - rayDirection(i % kRays, kRays, rotation)));
    worstOct = std::max(worstOct, glm::length(glm::vec2(o[1]) - octEncode(d)));
    worstTile =
        std::max(worstTile, glm::length(glm::vec2(o[1].z, o[1].w) -
                                        tileCoord(d, gpu_shared::kProbeIrradianceInterior)));
    worstDecode = std::max(worstDecode, glm::length(glm::vec3(o[2]) - octDecode(glm::vec2(other))));
    constexpr std::uint32_t tile = gpu_shared::kProbeIrradianceTexels;
    const glm::uvec2 src =
        borderSource({(i % (tile * tile)) % tile, (i % (tile * tile)) / tile}, tile);
    borderMismatches += o[3].x != static_cast<float>(src.x) || o[3].y != static_cast<float>(src.y);
    worstW = std::max(worstW, std::abs(o[3].z - chebyshevWeight({4.0f, 17.0f}, other.z,
                                                                gpu_shared::kProbeMinVariance)));
    worstW = std::max(worstW, std::abs(o[3].w - backfaceWeight(d, {0, 0, 1})));
  }
  std::printf(
      "[ measure  ] GPU-CPU max |diff|: ray dir %.2e, oct encode %.2e, tile coord %.2e, "
      "oct decode %.2e, weights %.2e\n",
      worstDir, worstOct, worstTile, worstDecode, worstW);
  EXPECT_LT(worstDir, 1e-5f);
  EXPECT_LT(worstOct, 1e-5f);
  EXPECT_LT(worstTile, 1e-4f);
  EXPECT_LT(worstDecode, 1e-5f);
  EXPECT_LT(worstW, 1e-5f);
  EXPECT_EQ(borderMismatches, 0);
}

}  // namespace
}  // namespace sdfstream::probe
