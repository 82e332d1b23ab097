// The probe update passes (probe_trace.comp, probe_blend.comp) against their CPU reference
// (ProbeUpdateCpu, the same shaders/probe_update.glsl compiled as C++), on the streamed bunny
// pack; and the white furnace through the real SDF traversal (sdfTraceStack) on both.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>

#include <gtest/gtest.h>

#include "gi/probe_update_cpu.h"
#include "gi/probe_volume.h"
#include "tests/gpu/gpu_test_fixture.h"
#include "tests/probes/probe_scenes.h"

namespace sdfstream::probe {
namespace {

// Largest |a - b| / max(|a|, |b|, floor) over all components (floor keeps near-zero values from
// dominating with pure rounding noise).
template <typename V, int N>
float worstRelative(std::span<const V> a, std::span<const V> b, float floor) {
  EXPECT_EQ(a.size(), b.size());
  float worst = 0.0f;
  for (std::size_t i = 0; i < std::min(a.size(), b.size()); ++i)
    for (int c = 0; c < N; ++c) {
      const float x = a[i][c], y = b[i][c];
      const float rel = std::abs(x - y) / std::max({std::abs(x), std::abs(y), floor});
      if (!(rel <= worst)) worst = std::isfinite(rel) ? rel : 1e30f;
    }
  return worst;
}

glm::vec3 randomUnit(std::mt19937& rng) {
  std::normal_distribution<float> g;
  const glm::vec3 d(g(rng), g(rng), g(rng));
  return glm::length(d) > 1e-3f ? glm::normalize(d) : glm::vec3(0.0f, 0.0f, 1.0f);
}

// Queries at random points of the volume's box (inflated by `margin` voxels), random normals
// and view directions.
std::vector<gpu_shared::ProbeQuery> randomQueries(const ProbeVolumeSettings& s, int count,
                                                  float margin, std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  const glm::vec3 lo = s.origin - glm::vec3(margin);
  const glm::vec3 size = glm::vec3(s.grid - glm::uvec3(1)) * s.spacing + glm::vec3(2.0f * margin);
  std::vector<gpu_shared::ProbeQuery> q(count);
  for (auto& x : q) {
    x.position = glm::vec4(lo + size * glm::vec3(u(rng), u(rng), u(rng)), 0.0f);
    x.normal = glm::vec4(randomUnit(rng), 0.0f);
    x.view = glm::vec4(randomUnit(rng), 0.0f);
  }
  return q;
}

class ProbeUpdateTest : public test::GpuTest {};

// GPU == CPU for three updates of a 3³ volume with 64 rays around the camera of the streamed
// bunny (sky + the bunny's albedo; the later updates exercise the multi-bounce feedback).
TEST_F(ProbeUpdateTest, GpuMatchesCpuOnStreamedBunny) {
  test::StreamedBunny b = test::streamBunny();
  ASSERT_TRUE(b.stack->settled());
  const CascadeStackImage img = b.stack->stackImage();
  ProbeVolumeSettings s;
  s.grid = glm::uvec3(3);
  s.raysPerProbe = 64;
  s.spacing = 16.0f;
  // Centred half-way from the camera to the point it looks at (0, 0.1, 0): amid the bunny.
  const glm::dvec3 middle = 0.5 * (b.camera + glm::dvec3(0.0, 0.1, 0.0));
  s.origin = img.toStack(middle) - glm::vec3(s.spacing);
  s.skyRadiance = glm::vec3(0.6f, 0.7f, 1.0f);
  s.irradianceHysteresis = 0.5f;
  s.depthHysteresis = 0.5f;
  s.maxDepth = 64.0f;
  ProbeUpdateCpu cpu(s);
  ProbeVolume gpu(ctx(), s);
  gpu.uploadScene(img);
  for (std::uint64_t frame = 0; frame < 3; ++frame) {
    cpu.update(img, frame);
    gpu.update(frame);
  }
  const auto gRays = gpu.downloadRays();
  const auto gIrr = gpu.downloadIrradiance();
  const auto gDepth = gpu.downloadDepth();
  int hits = 0, backfaces = 0;
  for (const glm::vec4& r : cpu.rays()) {
    hits += r.w < s.maxDepth;
    backfaces += r.x == 0.0f && r.w < s.maxDepth;
  }
  const float rays = worstRelative<glm::vec4, 4>(cpu.rays(), gRays, 1e-3f);
  const float irr = worstRelative<glm::vec4, 4>(cpu.irradiance(), gIrr, 1e-3f);
  const float depth = worstRelative<glm::vec2, 2>(cpu.depth(), gDepth, 1e-3f);
  double ms = 0.0;
  for (const auto& t : gpu.lastTimings()) ms += t.milliseconds;
  std::printf(
      "[figures] probe update GPU vs CPU (bunny, 27 probes x 64 rays, 3 updates, %d of "
      "%zu rays hit, %d backfaces): max rel diff rays %.2e, irradiance %.2e, depth %.2e; GPU %.3f "
      "ms\n",
      hits, cpu.rays().size(), backfaces, rays, irr, depth, ms);
  EXPECT_GT(hits, 300) << "the probes must see the bunny";
  EXPECT_LT(hits, int(cpu.rays().size())) << "and the sky";
  EXPECT_LE(rays, 1e-4f);
  EXPECT_LE(irr, 1e-4f);
  EXPECT_LE(depth, 1e-4f);
  const glm::vec3 centre = meanIrradiance(gIrr, 13, s.irradianceGamma);
  EXPECT_GT(centre.x + centre.y + centre.z, 0.0f);

  // irradiance(x, n, view): probe_sample.comp vs sampleIrradianceCpu on the same (GPU) probes.
  const auto queries = randomQueries(s, 4096, 4.0f, 9u);
  const auto gSample = gpu.sample(queries);
  const auto cSample = sampleIrradianceCpu(s, gIrr, gDepth, queries);
  const float sampled = worstRelative<glm::vec3, 3>(cSample, gSample, 1e-3f);
  float mean = 0.0f;
  for (const glm::vec3& e : cSample) mean += (e.x + e.y + e.z) / 3.0f / float(cSample.size());
  std::printf(
      "[figures] probe sample GPU vs CPU: %zu queries, mean irradiance %.4f, max rel "
      "diff %.2e\n",
      queries.size(), mean, sampled);
  EXPECT_LE(sampled, 1e-4f);
  EXPECT_GT(mean, 0.0f);
}

// White furnace. Inside a closed box whose walls all have Lambertian albedo rho and emitted
// radiance Le, the radiance is uniform in steady state: L = Le + rho * E / pi with the
// irradiance E = pi * L (uniform radiance over the hemisphere), so L = Le / (1 - rho) and every
// probe converges to  E = pi * Le / (1 - rho).  Traced through sdfTraceStack on an analytic box
// SDF (cascade 0, box [4, 36]³ voxels, probes at 12/20/28), bounce gain 1, sky 0.
TEST_F(ProbeUpdateTest, WhiteFurnaceConvergesToAnalyticIrradiance) {
  const std::uint32_t srgbByte = 188;
  const std::uint32_t albedo = srgbByte | srgbByte << 8 | srgbByte << 16 | 255u << 24;
  const std::uint32_t emission = 256u | 256u << 9 | 256u << 18 | 16u << 27;  // RGB9E5 of 1.0
  const double rho = std::pow((srgbByte / 255.0 + 0.055) / 1.055, 2.4);
  const double le = 1.0;
  const double expected = 3.141592653589793 * le / (1.0 - rho);
  test::AnalyticBox box(4.0f, 36.0f, albedo, emission);

  ProbeVolumeSettings s;
  s.grid = glm::uvec3(3);
  s.raysPerProbe = 64;
  s.origin = glm::vec3(12.0f);
  s.irradianceHysteresis = 0.6f;
  s.depthHysteresis = 0.6f;
  ProbeUpdateCpu cpu(s);
  ProbeVolume gpu(ctx(), s);
  gpu.uploadScene(box.image);
  const int frames = 80;
  int convergedAt = -1;  // first update after which the centre probe stays within 2%
  for (int frame = 0; frame < frames; ++frame) {
    cpu.update(box.image, std::uint64_t(frame));
    gpu.update(std::uint64_t(frame));
    const double e = meanIrradiance(cpu.irradiance(), 13, s.irradianceGamma).x;
    if (std::abs(e - expected) > 0.02 * expected)
      convergedAt = -1;
    else if (convergedAt < 0)
      convergedAt = frame + 1;
  }
  const auto gIrr = gpu.downloadIrradiance();
  int misses = 0;
  for (const glm::vec4& r : cpu.rays()) misses += r.x == 0.0f;  // a hit brings at least Le
  float worstTexel = 0.0f;
  for (std::uint32_t y = 0; y < gpu_shared::kProbeIrradianceInterior; ++y)
    for (std::uint32_t x = 0; x < gpu_shared::kProbeIrradianceInterior; ++x) {
      const glm::vec3 e = irradianceTexel(gIrr, 13, {x, y}, s.irradianceGamma);
      worstTexel = std::max(worstTexel, float(std::abs(e.x - expected) / expected));
    }
  const glm::vec3 eCpu = meanIrradiance(cpu.irradiance(), 13, s.irradianceGamma);
  const glm::vec3 eGpu = meanIrradiance(gIrr, 13, s.irradianceGamma);
  std::printf(
      "[figures] furnace rho %.4f Le %.1f: expected pi Le/(1-rho) = %.4f; centre probe "
      "after %d updates CPU %.4f (%+.3f%%), GPU %.4f (%+.3f%%), worst GPU texel %.3f%%, "
      "%d missed rays; within 2%% from update %d on (hysteresis %.2f)\n",
      rho, le, expected, frames, eCpu.x, 100.0 * (eCpu.x / expected - 1.0), eGpu.x,
      100.0 * (eGpu.x / expected - 1.0), 100.0 * worstTexel, misses, convergedAt,
      s.irradianceHysteresis);
  EXPECT_EQ(misses, 0);
  EXPECT_GT(convergedAt, 0);
  for (int c = 0; c < 3; ++c) {
    EXPECT_NEAR(eCpu[c], expected, 0.02 * expected);
    EXPECT_NEAR(eGpu[c], expected, 0.02 * expected);
  }
  EXPECT_LE(worstTexel, 0.02f);
  EXPECT_LE((worstRelative<glm::vec4, 4>(cpu.irradiance(), gIrr, 1e-3f)), 1e-4f);

  // Sampling the converged furnace anywhere inside the cage, any normal: the same E (the
  // sampling weights are normalised), on the GPU and on the CPU reference.
  const auto queries = randomQueries(s, 1024, 0.0f, 3u);
  const auto gSample = gpu.sample(queries);
  const auto cSample = sampleIrradianceCpu(s, cpu.irradiance(), cpu.depth(), queries);
  float worstSample = 0.0f;
  for (std::size_t i = 0; i < queries.size(); ++i)
    worstSample = std::max({worstSample, float(std::abs(gSample[i].x - expected) / expected),
                            float(std::abs(cSample[i].x - expected) / expected)});
  std::printf("[figures] furnace irradiance(x, n) at %zu random receivers: worst %.3f%% off\n",
              queries.size(), 100.0 * worstSample);
  EXPECT_LE(worstSample, 0.02f);
}

}  // namespace
}  // namespace sdfstream::probe
