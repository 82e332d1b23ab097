// The trace shader on Vulkan vs the CPU reference of the same math (sdf_trace.glsl) on the same
// cascade: identical hit/miss, hit distances within 1e-3 voxel, same materials, normals close.
#include <gtest/gtest.h>

#include <cstdio>

#include "gi/gpu_tracer.h"
#include "tests/support/gpu_test.h"
#include "tests/trace/trace_fixture.h"

namespace sdfstream {
namespace {

class TraceGpuVsCpu : public test::GpuTest {};

TEST_F(TraceGpuVsCpu, BunnyRaysMatchTheCpuReference) {
  test::TraceScene s = test::makeBunnyScene();
  auto rays = test::toCascadeRays(test::randomRaysAround(s.triangles, 20000, 99), s.cascade);
  TraceSettings settings;
  auto cpu = traceRaysCpu(s.cascade, rays, settings);
  GpuTracer tracer(ctx());
  tracer.setCascade(s.cascade);
  auto gpuHits = tracer.trace(rays, settings);
  ASSERT_EQ(gpuHits.size(), cpu.size());

  int hitCount = 0, flagMismatch = 0, farT = 0, materialMismatch = 0;
  double maxDt = 0.0;
  for (size_t i = 0; i < cpu.size(); ++i) {
    if (gpuHits[i].flags != cpu[i].flags) {
      ++flagMismatch;
      continue;
    }
    if (!(cpu[i].flags & gpu_shared::kHitFlagHit)) continue;
    ++hitCount;
    double dt = std::abs(double(gpuHits[i].normalT.w) - cpu[i].normalT.w);
    maxDt = std::max(maxDt, dt);
    if (dt > 1e-3) ++farT;
    if (gpuHits[i].albedo != cpu[i].albedo || gpuHits[i].emission != cpu[i].emission)
      ++materialMismatch;
    EXPECT_GT(glm::dot(glm::vec3(gpuHits[i].normalT), glm::vec3(cpu[i].normalT)), 0.999f) << i;
  }
  std::printf("[figures] GPU (%s) vs CPU trace: %zu rays, %d hits, %d hit/miss mismatches, "
              "max |dt| %.2e voxel, %d beyond 1e-3, %d material mismatches\n",
              ctx().deviceName().c_str(), cpu.size(), hitCount, flagMismatch, maxDt, farT,
              materialMismatch);
  EXPECT_GT(hitCount, 5000);
  EXPECT_EQ(flagMismatch, 0);
  EXPECT_EQ(farT, 0);
  EXPECT_EQ(materialMismatch, 0);
}

TEST_F(TraceGpuVsCpu, EmptyCascadeMissesEverything) {
  World empty;
  empty.voxelSize = 0.1;
  CascadeImage c = buildCascade(empty, glm::ivec3(0));
  std::vector<gpu_shared::TraceRay> rays(100);
  for (size_t i = 0; i < rays.size(); ++i) {
    rays[i].originTMin = glm::vec4(1.0f + i, 64.0f, 64.0f, 0.0f);
    rays[i].dirTMax = glm::vec4(glm::normalize(glm::vec3(0.3f, 1.0f, -0.2f)), 1e30f);
  }
  GpuTracer tracer(ctx());
  tracer.setCascade(c);
  for (const auto& h : tracer.trace(rays, TraceSettings{})) {
    EXPECT_EQ(h.flags, 0u);
    EXPECT_LE(h.steps, 4u);  // empty space is skipped by page bounds, not marched
  }
}

}  // namespace
}  // namespace sdfstream
