// The probe field: GPU passes against their CPU reference (the same
// shaders/probe_field.glsl compiled as C++) on the streamed bunny, and the white furnace through
// the whole chain (light cache -> probe trace -> blend -> cascade-blended sampling).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "gi/probe_math.h"
#include "tests/probes/gi_harness.h"
#include "tests/probes/probe_field_checks.h"
#include "tests/support/analytic_stack.h"
#include "tests/support/gpu_test.h"
#include "tests/support/streamed_bunny.h"

namespace sdfstream::probe {
namespace {

class ProbeFieldTest : public test::GpuTest {};

// GPU == CPU for four frames of a 3-cascade field (5³ probes each, 32 rays) around the camera
// of the streamed bunny: sun + sky, hit cache on, states, relocation; every stored texel, probe
// state and statistic, and irradiance queries across the cascades.
ProbeFieldSettings bunnyFieldSettings() {
  ProbeFieldSettings s;
  s.spacingBricks = 4;
  s.raysPerProbe = 32;
  s.states = true;
  return s;
}

// Depth texels whose mean depth agrees within 1e-3 (relative above 1 voxel).
template <class Cpu, class Gpu>
std::size_t depthTexelsWithin(const Cpu& cpu, const Gpu& gpu) {
  std::size_t close = 0;
  for (std::size_t i = 0; i < cpu.size(); ++i)
    close += std::abs(cpu[i].x - gpu[i].x) <= 1e-3f * std::max(1.0f, std::abs(cpu[i].x));
  return close;
}

// Four frames of the GPU and CPU fields around the bunny's camera: sun + sky.
void warmBunnyField(test::GiHarness& h, const test::StreamedBunny& b,
                    const CascadeStackImage& img) {
  ProbeFrameInputs in = test::lightBunnyScene(h, img, b.camera);
  for (std::uint64_t frame = 0; frame < 4; ++frame) {
    in.lightsChanged = frame == 0;
    h.step(img, in, frame);
  }
}

// Border texels (of every probe's tile) whose value differs from their source's.
template <typename T>
std::uint32_t bordersUnlikeTheirSource(const std::vector<T>& atlas, std::uint32_t tile) {
  std::uint32_t unlike = 0;
  for (std::size_t p = 0; p + std::size_t(tile) * tile <= atlas.size();
       p += std::size_t(tile) * tile)
    for (std::uint32_t y = 0; y < tile; ++y)
      for (std::uint32_t x = 0; x < tile; ++x) {
        const glm::uvec2 src = borderSource({x, y}, tile);
        if (atlas[p + y * tile + x] != atlas[p + src.y * tile + src.x]) ++unlike;
      }
  return unlike;
}

TEST_F(ProbeFieldTest, GpuMatchesCpuOnStreamedBunny) {
  test::StreamedBunny b = test::streamBunny();
  const CascadeStackImage img = b.stack->stackImage();
  test::GiHarness h(ctx(), bunnyFieldSettings(), 3);
  warmBunnyField(h, b, img);
  ProbeFrameInputs in;
  in.cameraWorld = b.camera;
  in.viewDirection = glm::vec3(glm::normalize(glm::dvec3(0.0, 0.1, 0.0) - b.camera));
  const ProbeFieldCpu& cpu = *h.cpuField;
  const auto gIrr = h.gpuField->downloadIrradiance();
  const auto gDepth = h.gpuField->downloadDepth();
  const auto gData = h.gpuField->downloadProbeData();
  const float irr = test::worstRelative<glm::vec4, 4>(cpu.irradiance(), gIrr, 1e-3f);
  const float depth = test::worstRelative<glm::vec2, 2>(cpu.depth(), gDepth, 1e-3f);
  const float data = test::worstRelative<glm::vec4, 4>(cpu.probeData(), gData, 1e-3f);
  const ProbeFieldStats& cs = cpu.lastStats();
  const ProbeFieldStats& gs = h.gpuField->lastStats();
  std::printf(
      "[figures] probe field GPU vs CPU (bunny, 3 cascades x 125 probes x 32 rays, 4 frames): "
      "max rel diff irradiance %.2e, depth %.2e, probe data %.2e; states off/sleep/awake/vigilant "
      "%u/%u/%u/%u; last frame %u probes, %u rays traced, %u cached; GPU %.3f ms\n",
      irr, depth, data, cs.states[0], cs.states[1], cs.states[2], cs.states[3], cs.probesUpdated,
      cs.raysTraced, cs.raysCached, h.gpuField->lastMilliseconds());
  // Not bit-exact: the GPU's sin/cos (Fibonacci directions, rotations) differ from libm's in
  // the last bits, so a ray grazing a silhouette may hit on one side and miss on the other; a
  // depth texel is dominated by a few rays (power-cosine 50). Stated bounds: irradiance 1%,
  // depth moments 10% worst texel, and 99% of depth texels within 1e-3.
  EXPECT_LE(irr, 1e-2f);
  EXPECT_LE(depth, 1e-1f);
  EXPECT_LE(data, 1e-5f);
  EXPECT_GE(double(depthTexelsWithin(cpu.depth(), gDepth)), 0.99 * double(gDepth.size()));
  // The blend writes the tiles' borders with their interior texels: on the GPU too, every border
  // texel holds exactly its source's value.
  EXPECT_EQ(bordersUnlikeTheirSource(gIrr, gpu_shared::kProbeIrradianceTexels), 0u);
  EXPECT_EQ(bordersUnlikeTheirSource(gDepth, gpu_shared::kProbeDepthTexels), 0u);
  EXPECT_EQ(cs.probesUpdated, gs.probesUpdated);
  EXPECT_EQ(cs.raysTraced, gs.raysTraced);
  EXPECT_EQ(cs.raysCached, gs.raysCached);
  // lavapipe's LLVM may contract a few multiply-adds outside the `precise` trace math.
  EXPECT_NEAR(double(cs.steps), double(gs.steps), 2e-3 * double(cs.steps));
  for (int i = 0; i < 4; ++i) EXPECT_EQ(cs.states[i], gs.states[i]) << "state " << i;
  // Four more frames reuse the four rotation slots: every ray comes from the hit cache. A cached
  // normal is quantised (13 + 13 bits) from the normal each side computed, so a one-ulp
  // difference can land in the neighbouring code: looser bound, stated here.
  for (std::uint64_t frame = 4; frame < 8; ++frame) h.step(img, in, frame);
  EXPECT_GT(cpu.lastStats().raysCached, 0u);
  EXPECT_EQ(cpu.lastStats().raysCached, h.gpuField->lastStats().raysCached);
  const float cachedIrr =
      test::worstRelative<glm::vec4, 4>(cpu.irradiance(), h.gpuField->downloadIrradiance(), 1e-3f);
  std::printf(
      "[figures] probe field GPU vs CPU after 4 cached frames: max rel diff irradiance %.2e\n",
      cachedIrr);
  EXPECT_LE(cachedIrr, 2e-2f);

  const auto queries = test::randomQueries(img, 0, 2048, 7u);
  const auto gSample = h.sampleGpu(queries);
  const auto cSample = cpu.sample(img, queries);
  const float sampled = test::worstRelative<glm::vec3, 3>(cSample, gSample, 1e-3f);
  float mean = 0.0f;
  for (const glm::vec3& e : cSample) mean += (e.x + e.y + e.z) / 3.0f / float(cSample.size());
  std::printf(
      "[figures] field irradiance(x, n, view) GPU vs CPU: %zu queries, mean %.4f, max rel diff "
      "%.2e\n",
      queries.size(), mean, sampled);
  EXPECT_LE(sampled, 1e-3f);
  EXPECT_GT(mean, 0.0f);
}

// Sampling at half resolution (probe_sample.comp's half mode, then probe_upsample.comp) against
// the CPU reference of the same order and upsample, on an odd-sized image (partial tiles and
// blocks at the edges) of a floor, a wall across it and pixels without a surface.
TEST_F(ProbeFieldTest, HalfResolutionSamplingMatchesCpu) {
  test::StreamedBunny b = test::streamBunny();
  const CascadeStackImage img = b.stack->stackImage();
  test::GiHarness h(ctx(), bunnyFieldSettings(), 3);
  warmBunnyField(h, b, img);
  const std::uint32_t w = 37, hgt = 29;
  const glm::vec3 origin(img.params[0].offsetScale);
  std::vector<gpu_shared::ProbeQuery> image;
  std::size_t holes = 0;
  for (std::uint32_t y = 0; y < hgt; ++y)
    for (std::uint32_t x = 0; x < w; ++x) {
      gpu_shared::ProbeQuery q{};
      const bool wall = x >= 12 && x <= 16;
      q.position = glm::vec4(origin + glm::vec3(30.0f + 1.5f * float(x), wall ? 44.0f : 40.0f,
                                                30.0f + 1.5f * float(y)),
                             0.0f);
      q.normal = wall ? glm::vec4(1, 0, 0, 0) : glm::vec4(0, 1, 0, 0);
      q.view = glm::vec4(glm::normalize(glm::vec3(0.2f, 1.0f, 0.3f)), 0.0f);
      if ((x + w * y) % 13 == 5) {
        q.normal = glm::vec4(0.0f);
        ++holes;
      }
      image.push_back(q);
    }
  for (const std::uint32_t block : {2u, 4u}) {
    const auto gpu = h.gpuField->sampleHalfResolution(*h.scene, h.lightGpu->radianceBuffer(), image,
                                                      w, hgt, block);
    const auto cpu = h.cpuField->sampleHalfResolution(img, image, w, hgt, block);
    ASSERT_EQ(gpu.size(), image.size());
    const float worst = test::worstRelative<glm::vec3, 3>(cpu, gpu, 1e-3f);
    float mean = 0.0f;
    for (std::size_t i = 0; i < image.size(); ++i) {
      mean += (cpu[i].x + cpu[i].y + cpu[i].z) / 3.0f / float(image.size());
      if (image[i].normal == glm::vec4(0.0f)) {
        EXPECT_EQ(gpu[i], glm::vec3(0.0f)) << i;
        EXPECT_EQ(cpu[i], glm::vec3(0.0f)) << i;
      }
    }
    std::vector<std::string> names;
    for (const auto& t : h.gpuField->lastTimings()) names.push_back(t.name);
    std::printf(
        "[figures] reduced-resolution sampling (%ux%u blocks) GPU vs CPU: %ux%u pixels, %zu "
        "without a surface, mean %.4f, max rel diff %.2e\n",
        block, block, w, hgt, holes, mean, worst);
    EXPECT_LE(worst, 1e-3f) << block;
    EXPECT_GT(mean, 0.0f) << block;
    EXPECT_EQ(names, (std::vector<std::string>{"probe_sample", "probe_upsample"}));
  }
  EXPECT_THROW(
      h.gpuField->sampleHalfResolution(*h.scene, h.lightGpu->radianceBuffer(), image, w, hgt, 3),
      std::invalid_argument);
}

// probe_blend.comp stages a probe's rays in shared memory 128 at a time; with more rays than
// that each texel sums chunk after chunk, re-staging them for each of the thread's texels. 160
// rays (a full chunk and a partial one) against the CPU's single pass over all of them, with the
// bounds of the test above.
TEST_F(ProbeFieldTest, BlendOverSeveralRayChunksMatchesCpu) {
  test::StreamedBunny b = test::streamBunny();
  const CascadeStackImage img = b.stack->stackImage();
  ProbeFieldSettings s = bunnyFieldSettings();
  s.raysPerProbe = 160;
  test::GiHarness h(ctx(), s, 3);
  warmBunnyField(h, b, img);
  const ProbeFieldCpu& cpu = *h.cpuField;
  ASSERT_GT(cpu.lastStats().probesUpdated, 0u);
  const auto gDepth = h.gpuField->downloadDepth();
  const float irr =
      test::worstRelative<glm::vec4, 4>(cpu.irradiance(), h.gpuField->downloadIrradiance(), 1e-3f);
  const auto c = cpu.depth();
  const std::size_t close = depthTexelsWithin(c, gDepth);
  std::printf(
      "[figures] 160 rays a probe, GPU vs CPU: max rel diff irradiance %.2e, depth texels within "
      "1e-3: %zu of %zu\n",
      irr, close, c.size());
  EXPECT_LE(irr, 1e-2f);
  EXPECT_GE(double(close), 0.99 * double(c.size()));
}

// Pixels come to probe_sample.comp in groups of neighbours: kProbeSampleShareLanes receivers a few
// hundredths of a voxel apart, in the same cage, split its open SDF tests (probeGroupSharesCage).
// GPU == CPU on such queries; against every query tracing its own tests (PerQuery, the per-pixel
// shader's answer) they differ only where a probe sees one receiver and not its neighbour.
// Receivers farther apart than the tolerance (half a voxel of the cage's cascade) trace their own.
TEST_F(ProbeFieldTest, NeighbouringQueriesSplitTheirSdfTests) {
  test::StreamedBunny b = test::streamBunny();
  const CascadeStackImage img = b.stack->stackImage();
  test::GiHarness h(ctx(), bunnyFieldSettings(), 3);
  warmBunnyField(h, b, img);
  const ProbeFieldCpu& cpu = *h.cpuField;
  auto quads = [&](float apart) {
    std::vector<gpu_shared::ProbeQuery> q;
    for (const gpu_shared::ProbeQuery& x : test::randomQueries(img, 0, 1024, 11u))
      for (std::uint32_t k = 0; k < gpu_shared::kProbeSampleShareLanes; ++k) {
        gpu_shared::ProbeQuery n = x;
        n.position += glm::vec4(apart * float(k % 2), apart * float(k / 2), 0.0f, 0.0f);
        q.push_back(n);
      }
    return q;
  };
  using Traces = ProbeFieldCpu::SampleTraces;
  const auto near = quads(0.03f);
  ProbeFieldCpu::SampleCounts counts;
  const auto shared = cpu.sample(img, near, Traces::GroupsShareTraces, &counts);
  const auto own = cpu.sample(img, near, Traces::PerQuery);
  const float gpuVsCpu = test::worstRelative<glm::vec3, 3>(shared, h.sampleGpu(near), 1e-3f);
  std::size_t differ = 0;
  double meanDiff = 0.0;
  for (std::size_t i = 0; i < own.size(); ++i) {
    const float a = own[i].x + own[i].y + own[i].z, d = shared[i].x + shared[i].y + shared[i].z;
    const double rel = std::abs(double(d) - double(a)) / std::max(1e-3, double(a));
    differ += rel > 1e-3 ? 1 : 0;
    meanDiff += rel / double(own.size());
  }
  std::printf(
      "[figures] groups 0.03 voxels apart: %llu of %llu cages shared, %llu SDF tests traced "
      "instead of %llu (%.2f); GPU vs CPU max rel diff %.2e; against per-query tests %zu of %zu "
      "differ by > 0.1%%, mean rel diff %.2e\n",
      (unsigned long long)counts.sharedCages, (unsigned long long)counts.cages,
      (unsigned long long)counts.traces, (unsigned long long)counts.ownTests,
      double(counts.traces) / double(std::max<std::uint64_t>(counts.ownTests, 1)), gpuVsCpu, differ,
      own.size(), meanDiff);
  EXPECT_LE(gpuVsCpu, 1e-3f);
  EXPECT_GE(double(counts.sharedCages), 0.9 * double(counts.cages));
  EXPECT_GT(counts.ownTests, 1000u);  // the SDF test is open often enough to tell
  EXPECT_LE(double(counts.traces), 0.5 * double(counts.ownTests));
  EXPECT_LE(double(differ), 0.01 * double(own.size()));
  EXPECT_LE(meanDiff, 1e-3);

  const auto far = quads(6.0f);  // beyond half a voxel of cascade 2 (4 voxels of cascade 0)
  const auto farShared = cpu.sample(img, far, Traces::GroupsShareTraces, &counts);
  const auto farOwn = cpu.sample(img, far, Traces::PerQuery);
  EXPECT_EQ(counts.sharedCages, 0u);
  EXPECT_LE((test::worstRelative<glm::vec3, 3>(farShared, farOwn, 1e-6f)), 1e-6f);
  EXPECT_LE((test::worstRelative<glm::vec3, 3>(farShared, h.sampleGpu(far), 1e-3f)), 1e-3f);
}

// White furnace. Inside a closed box whose walls all have Lambertian albedo rho and emitted
// radiance Le, the radiance is uniform in steady state: L = Le + rho * E / pi with the
// irradiance E = pi * L (uniform radiance over the hemisphere), so L = Le / (1 - rho) and every
// probe converges to  E = pi * Le / (1 - rho).  One cascade, box [4, 124]³ voxels, 9³ probes
// (7³ inside, the rest in the walls and switched off), no lights, sky 0, bounce gain 1.
TEST_F(ProbeFieldTest, WhiteFurnaceConvergesToAnalyticIrradiance) {
  const test::WhiteFurnaceBox furnace;
  const test::AnalyticStack& box = furnace.stack;
  const double rho = furnace.rho, expected = furnace.expected;
  ProbeFieldSettings s;
  s.spacingBricks = 2;
  s.raysPerProbe = 64;
  s.irradianceHysteresis = 0.6f;
  s.depthHysteresis = 0.6f;
  test::GiHarness h(ctx(), s, 1);
  ProbeFrameInputs in;
  in.cameraWorld = glm::dvec3(64.0);
  const int frames = 40;
  for (int frame = 0; frame < frames; ++frame)
    h.step(box.image, in, std::uint64_t(frame), frame == 0);
  const auto gIrr = h.gpuField->downloadIrradiance();
  const ProbeFieldCpu& cpu = *h.cpuField;
  double worstProbe = 0.0;
  int usable = 0;
  for (std::uint32_t g = 0; g < s.probesPerVolume(); ++g) {
    if (std::uint32_t(cpu.probeData()[g].w + 0.5f) == gpu_shared::kProbeOff) continue;
    ++usable;
    const glm::vec3 e = test::meanProbeIrradiance(gIrr, g, s.irradianceGamma);
    worstProbe = std::max(worstProbe, std::abs(e.x - expected) / expected);
  }
  const auto queries = test::boxWallQueries(furnace.lo, furnace.hi, 1024, 3u);
  const auto gSample = h.sampleGpu(queries);
  const auto cSample = cpu.sample(box.image, queries);
  double worstSample = 0.0;
  for (std::size_t i = 0; i < queries.size(); ++i)
    worstSample = std::max({worstSample, std::abs(gSample[i].x - expected) / expected,
                            std::abs(cSample[i].x - expected) / expected});
  std::printf(
      "[figures] furnace rho %.4f Le 1: expected pi Le/(1-rho) = %.4f; after %d frames %d "
      "probes on, worst probe %.3f%% off, worst of %zu irradiance(x,n) queries %.3f%% off; GPU vs "
      "CPU %.2e\n",
      rho, expected, frames, usable, 100.0 * worstProbe, queries.size(), 100.0 * worstSample,
      test::worstRelative<glm::vec4, 4>(cpu.irradiance(), gIrr, 1e-3f));
  EXPECT_GE(usable, 6 * 7 * 7);  // at least the probes next to the walls
  EXPECT_LE(worstProbe, 0.02);
  EXPECT_LE(worstSample, 0.02);
}

}  // namespace
}  // namespace sdfstream::probe
