// The engine-facing include (shaders/include/sdfstream/probe_sample.glsl): a shader of "an
// engine" (shaders/probe_sample_engine_selftest.comp, its own buffers first, the field's from
// binding 3 on) samples a converged probe field and must return exactly what ProbeField::sample
// returns for the same queries, in the field's coordinates and from world positions.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "gpu/buffer.h"
#include "gpu/command_batch.h"
#include "gpu/compute_pipeline.h"
#include "tests/support/gpu_test.h"
#include "tests/probes/gi_harness.h"
#include "tests/probes/probe_field_checks.h"
#include "tests/support/analytic_stack.h"

namespace sdfstream::probe {
namespace {

class ProbeSampleIncludeTest : public test::GpuTest {};

constexpr std::uint32_t kGrey = 160u | 160u << 8 | 160u << 16 | 255u << 24;
constexpr std::uint32_t kProbeBinding = 3;  // SDFSTREAM_PROBE_BINDING of the engine shader
constexpr std::uint32_t kIncludeBuffers = 8;

gpu::Buffer uploadBuffer(gpu::Context& ctx, const void* data, std::size_t bytes) {
  gpu::Buffer b(ctx, bytes, gpu::BufferKind::Upload);
  std::memcpy(b.mapped(), data, bytes);
  return b;
}
template <typename T>
gpu::Buffer uploadBuffer(gpu::Context& ctx, const std::vector<T>& v) {
  return uploadBuffer(ctx, v.data(), v.size() * sizeof(T));
}

// Receivers on the floor (y = 40) and on the pillar's four sides, half a voxel out, views on the
// normal's side; then points anywhere in cascade 1's window (both cascades and their blend).
std::vector<gpu_shared::ProbeQuery> sceneQueries(const CascadeStackImage& img) {
  std::mt19937 rng(17u);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  std::vector<gpu_shared::ProbeQuery> q;
  auto add = [&](glm::vec3 p, glm::vec3 n) {
    glm::vec3 v = test::randomUnit(rng);
    if (glm::dot(v, n) < 0.0f) v = -v;
    q.push_back({glm::vec4(p, 0.0f), glm::vec4(n, 0.0f), glm::vec4(v, 0.0f)});
  };
  for (int i = 0; i < 1024; ++i)
    add(glm::vec3(8.0f + 112.0f * u(rng), 40.5f, 8.0f + 112.0f * u(rng)), glm::vec3(0, 1, 0));
  for (int i = 0; i < 512; ++i) {
    const int side = i % 4, axis = side < 2 ? 0 : 2;
    glm::vec3 p(56.0f + 16.0f * u(rng), 40.5f + 35.0f * u(rng), 56.0f + 16.0f * u(rng));
    glm::vec3 n(0.0f);
    n[axis] = side % 2 == 0 ? -1.0f : 1.0f;
    p[axis] = side % 2 == 0 ? 55.5f : 72.5f;
    add(p, n);
  }
  for (const gpu_shared::ProbeQuery& r : test::randomQueries(img, 1, 512, 23u)) q.push_back(r);
  return q;
}

// The engine shader over `queries` (positions world metres when `world`), against the field's
// buffers bound in the include's order (its header comment).
std::vector<glm::vec3> sampleThroughInclude(gpu::Context& ctx, const test::GiHarness& h,
                                            const ProbeFieldFrame& frame,
                                            const std::vector<gpu_shared::ProbeQuery>& queries,
                                            bool world) {
  const gpu::Buffer q = uploadBuffer(ctx, queries);
  gpu::Buffer results(ctx, queries.size() * sizeof(glm::vec4), gpu::BufferKind::Readback);
  const gpu::Buffer frameBuf = uploadBuffer(ctx, &frame.constants, sizeof frame.constants);
  const gpu::Buffer volumes = uploadBuffer(ctx, frame.volumes);
  const gpu::Buffer data = uploadBuffer(ctx, h.gpuField->downloadProbeData());
  const gpu::Buffer irradiance = uploadBuffer(ctx, h.gpuField->downloadIrradiance());
  const gpu::Buffer depth = uploadBuffer(ctx, h.gpuField->downloadDepth());
  // Bindings 0-2 are the engine's (2 unused by the shader); the field's eight follow.
  const std::vector<const gpu::Buffer*> bindings = {&q,
                                                    &results,
                                                    &q,
                                                    &frameBuf,
                                                    &volumes,
                                                    &data,
                                                    &irradiance,
                                                    &depth,
                                                    &h.scene->pageTables(),
                                                    &h.scene->distance(),
                                                    &h.scene->params()};
  EXPECT_EQ(bindings.size(), kProbeBinding + kIncludeBuffers);
  const gpu::ComputePipeline pipeline(
      ctx, gpu::ShaderId::probe_sample_engine_selftest,
      gpu::PipelineDesc{kProbeBinding + kIncludeBuffers, 16, glm::uvec3(64, 1, 1)});
  const glm::uvec4 push(std::uint32_t(queries.size()), world ? 1u : 0u, 0u, 0u);
  gpu::CommandBatch batch = ctx.beginBatch();
  batch.dispatch("probe_sample_engine", pipeline, bindings, &push, sizeof push,
                 glm::uvec3(std::uint32_t(queries.size()), 1, 1));
  batch.submitAndWait();
  std::vector<glm::vec3> out(queries.size());
  const auto* r = static_cast<const glm::vec4*>(results.mapped());
  for (std::size_t i = 0; i < out.size(); ++i) out[i] = glm::vec3(r[i]);
  return out;
}

std::size_t bitEqualCount(const std::vector<glm::vec3>& a, const std::vector<glm::vec3>& b) {
  std::size_t same = 0;
  for (std::size_t i = 0; i < std::min(a.size(), b.size()); ++i)
    same += std::memcmp(&a[i], &b[i], sizeof(glm::vec3)) == 0;
  return same;
}

// A floor (y < 40) with a 16 x 36 x 16 pillar on it and a roof 10 voxels above part of it, in a
// 2-cascade stack placed off the world origin with 0.25 m voxels, grey, sun and sky; the GPU
// field converged over 12 frames (9³ probes per cascade, 64 rays). The include's answers must be
// bit-identical to ProbeField::sample's: the same GLSL functions on the same data (both shaders
// compile shaders/probe_sample.glsl, so the driver sees the same expressions to contract or not).
// They must also be meaningful -- positive and varying across receivers (open floor, floor under
// the roof, the pillar's sides, empty space) -- so that a swapped or misplaced binding, which
// reads another buffer's words, cannot pass.
TEST_F(ProbeSampleIncludeTest, EngineShaderMatchesProbeFieldSample) {
  auto scene = [](glm::vec3 p, float) {
    const float floor = p.y - 40.0f;
    const float pillar =
        -test::insideBox(glm::vec3(56.0f, 20.0f, 56.0f), glm::vec3(72.0f, 76.0f, 72.0f))(p);
    const float roof =
        -test::insideBox(glm::vec3(12.0f, 50.0f, 12.0f), glm::vec3(44.0f, 54.0f, 116.0f))(p);
    return std::min({floor, pillar, roof});
  };
  test::AnalyticStack stack(2, scene, [](glm::vec3) { return glm::uvec2(kGrey, 0u); });
  CascadeStackImage& img = stack.image;
  img.cascade0MinWorld = glm::dvec3(-37.5, 12.25, 250.0);
  img.voxelSize0 = 0.25;

  ProbeFieldSettings s;
  s.spacingBricks = 2;
  s.raysPerProbe = 64;
  test::GiHarness h(ctx(), s, 2, false, true);
  h.sky.zenith = glm::vec4(0.4f, 0.5f, 0.8f, 0.0f);
  h.sky.horizon = glm::vec4(0.6f, 0.6f, 0.6f, 0.0f);
  h.lights = test::sunLights(img, glm::vec3(-0.4f, -1.0f, -0.3f), 3.0f);
  // The field keeps its frame constants to itself: a builder fed the same frames rebuilds them
  // (ProbeFieldFrameBuilder is deterministic), as GiHarness::step feeds ProbeField::update.
  ProbeFieldFrameBuilder replay(s);
  ProbeFieldFrame frame;
  ProbeFrameInputs in;
  in.cameraWorld = img.cascade0MinWorld + glm::dvec3(64.0, 60.0, 20.0) * img.voxelSize0;
  in.viewDirection = glm::vec3(0.0f, -0.2f, 1.0f);
  for (std::uint64_t f = 0; f < 12; ++f) {
    in.lightsChanged = f == 0;
    h.step(img, in, f, f == 0);
    ProbeFrameInputs withSky = in;
    withSky.sky = h.sky;
    frame = replay.build(img, withSky, f);
  }

  // Field coordinates.
  const std::vector<gpu_shared::ProbeQuery> queries = sceneQueries(img);
  const std::vector<glm::vec3> expected = h.sampleGpu(queries);
  const std::vector<glm::vec3> got = sampleThroughInclude(ctx(), h, frame, queries, false);
  const std::size_t same = bitEqualCount(expected, got);

  // World positions: the reference queries the field at the stack position the include derives
  // from them, (world - corner) * (1 / voxel) in float (no fused multiply-add possible).
  std::vector<gpu_shared::ProbeQuery> worldQueries = queries, derived = queries;
  const glm::vec4 w = frame.constants.worldToStack;
  for (std::size_t i = 0; i < queries.size(); ++i) {
    const glm::vec3 p = glm::vec3(img.cascade0MinWorld +
                                  glm::dvec3(glm::vec3(queries[i].position)) * img.voxelSize0);
    worldQueries[i].position = glm::vec4(p, 0.0f);
    derived[i].position = glm::vec4((p - glm::vec3(w)) * w.w, 0.0f);
  }
  const std::vector<glm::vec3> expectedWorld = h.sampleGpu(derived);
  const std::vector<glm::vec3> gotWorld = sampleThroughInclude(ctx(), h, frame, worldQueries, true);
  const std::size_t sameWorld = bitEqualCount(expectedWorld, gotWorld);

  // Meaningful: the floor's lit part against its darkest receiver, and how many distinct values.
  double mean = 0.0, floorMin = 1e30, floorMax = 0.0;
  std::vector<float> lum(expected.size());
  for (std::size_t i = 0; i < expected.size(); ++i) {
    lum[i] = (expected[i].x + expected[i].y + expected[i].z) / 3.0f;
    EXPECT_TRUE(std::isfinite(lum[i])) << "query " << i;
    mean += lum[i] / double(expected.size());
    if (i < 1024) {  // the floor receivers
      floorMin = std::min(floorMin, double(lum[i]));
      floorMax = std::max(floorMax, double(lum[i]));
    }
  }
  std::vector<float> distinct = lum;
  std::sort(distinct.begin(), distinct.end());
  const std::size_t distinctCount =
      std::unique(distinct.begin(), distinct.end()) - distinct.begin();
  const float worldRel = test::worstRelative<glm::vec3, 3>(expected, gotWorld, 1e-3f);
  std::printf(
      "[figures] engine include (binding 3) vs ProbeField::sample, %zu queries: bit-identical "
      "%zu (field coordinates), %zu (world positions, 0.25 m voxels); mean irradiance %.4f, floor "
      "%.4f..%.4f, %zu distinct values; world vs field-coordinate queries max rel diff %.2e\n",
      queries.size(), same, sameWorld, mean, floorMin, floorMax, distinctCount, worldRel);
  EXPECT_EQ(same, queries.size());
  EXPECT_EQ(sameWorld, queries.size());
  EXPECT_GT(mean, 0.05);
  EXPECT_GT(floorMax, 2.0 * floorMin);  // open floor against the floor under the roof
  EXPECT_GT(distinctCount, queries.size() * 9 / 10);
}

}  // namespace
}  // namespace sdfstream::probe
