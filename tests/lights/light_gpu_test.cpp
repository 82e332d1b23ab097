// The GPU light cache (light_cache.comp) against its CPU reference (the same light_math.glsl
// compiled as C++), dirty-page updates and emission pass-through. Validation must stay silent
// (GpuTest).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>

#include <gtest/gtest.h>

#include "gi/gpu_stack_scene.h"
#include "gi/light_cache.h"
#include "tests/lights/light_scenes.h"
#include "tests/support/gpu_test.h"

namespace sdfstream {
namespace {
using test::AnalyticScene;

class LightGpuTest : public test::GpuTest {};

// Floor, a plate, a post and a glowing block: every kind of cell the cache writes.
float sdMixed(glm::vec3 p) {
  float d = std::min(test::sdFloor(p), test::sdBox(p, {40, 50, 40}, {60, 52, 88}));
  d = std::min(d, test::sdBox(p, {70, 40, 56}, {74, 62, 60}));
  return std::min(d, test::sdBox(p, {80.5f, 40, 70.5f}, {85.5f, 44, 75.5f}));
}
std::uint32_t mixedAlbedo(glm::vec3 c) {
  return test::rgba8(std::uint32_t(c.x * 2) & 255u, 160u, std::uint32_t(c.z * 3) & 255u);
}
std::uint32_t mixedEmission(glm::vec3 c) {
  return c.x > 80 && c.z > 70 && c.y < 45 ? gpu_shared::packRgb9e5({4.0f, 1.0f, 0.25f}) : 0u;
}

std::vector<gpu_shared::GpuLight> mixedLights() {
  return {test::sunLight({0.3f, 0.85f, 0.2f}, 2.5f, 8.0f, {1.0f, 0.95f, 0.9f}),
          test::pointLight({66.0f, 56.0f, 50.0f}, 3.0f, 4.0f, 16.0f, {0.9f, 0.8f, 1.0f}),
          test::spotLight({50.0f, 62.0f, 70.0f}, {0.2f, -1.0f, 0.1f}, 15.0f, 35.0f, 20.0f, 4.0f)};
}

// Pages x 4..11, y 3..7, z 5..10 (the objects and the floor under them).
std::vector<std::uint32_t> mixedPages(const AnalyticScene& s) {
  return s.residentPagesIn({4, 3, 5}, {11, 7, 10});
}

struct Difference {
  std::size_t differing = 0;
  float maxRelative = 0.0f;  // of the largest channel
};
Difference compare(std::span<const std::uint32_t> a, std::span<const std::uint32_t> b) {
  Difference d;
  for (std::size_t i = 0; i < std::min(a.size(), b.size()); ++i) {
    if (a[i] == b[i]) continue;
    ++d.differing;
    const glm::vec3 x = test::decode(a[i]), y = test::decode(b[i]);
    const float scale = std::max({x.x, x.y, x.z, y.x, y.y, y.z});
    const glm::vec3 e = glm::abs(x - y);
    d.maxRelative = std::max(d.maxRelative, std::max({e.x, e.y, e.z}) / scale);
  }
  return d;
}

// Two cascades, every resident page of both: the stack walk, the cascade offsets and the
// finest-cascade shadow offset all run on both sides.
TEST_F(LightGpuTest, MatchesCpuReferenceOnSunPointAndSpot) {
  AnalyticScene scene(sdMixed, mixedAlbedo, mixedEmission, 0.25, 2);
  GpuStackScene gpuScene(ctx());
  gpuScene.uploadAll(scene.image);
  const auto lights = mixedLights();
  gpu_shared::GpuSky sky{};
  const std::vector<std::uint32_t> pages = scene.residentPages();
  LightCacheCpu cpu;
  const auto t0 = std::chrono::steady_clock::now();
  cpu.update(scene.image, lights, sky, pages, 0.25);
  const auto t1 = std::chrono::steady_clock::now();
  LightCache gpu(ctx());
  gpu.update(gpuScene, lights, sky, pages, 0.25);
  const auto t2 = std::chrono::steady_clock::now();
  const std::vector<std::uint32_t> got = gpu.downloadRadiance();
  ASSERT_EQ(got.size(), cpu.radiance().size());
  std::size_t lit = 0;
  for (std::uint32_t w : got) lit += test::decode(w).x > 0.0f;
  ASSERT_GT(lit, 50000u);  // the comparison covers many lit cells, not just zeros
  const Difference d = compare(got, cpu.radiance());
  std::printf(
      "[light] %zu pages, %zu cells lit: GPU vs CPU %zu of %zu words differ, max relative "
      "%.3g; CPU %.0f ms, GPU %.0f ms (pass %.0f ms)\n",
      pages.size(), lit, d.differing, got.size(), d.maxRelative,
      std::chrono::duration<double, std::milli>(t1 - t0).count(),
      std::chrono::duration<double, std::milli>(t2 - t1).count(),
      gpu.lastTimings().empty() ? 0.0 : gpu.lastTimings()[0].milliseconds);
  // Same math and the same rounding rules (-ffp-contract=off, `precise`): expect bit-identical
  // words; allow a few RGB9E5 steps (pow/exp differ by an ulp between libm and the driver) on at
  // most 0.1% of the words.
  EXPECT_LE(d.differing, got.size() / 1000);
  EXPECT_LE(d.maxRelative, 0.01f);
  ASSERT_EQ(gpu.lastTimings().size(), 1u);
  EXPECT_EQ(gpu.lastTimings()[0].name, "light_cache");
  EXPECT_EQ(gpu.pagesRelitLastUpdate(), pages.size());
}

TEST_F(LightGpuTest, EmptyListDispatchesNothingAndSubsetChangesOnlyItsSlots) {
  AnalyticScene scene(sdMixed, mixedAlbedo, mixedEmission, 0.25);
  GpuStackScene gpuScene(ctx());
  gpuScene.uploadAll(scene.image);
  std::vector<gpu_shared::GpuLight> lights = mixedLights();
  const std::vector<std::uint32_t> pages = mixedPages(scene);
  LightCache gpu(ctx());
  gpu.update(gpuScene, lights, {}, pages, 0.25);
  const std::vector<std::uint32_t> before = gpu.downloadRadiance();

  gpu.update(gpuScene, lights, {}, {}, 0.25);
  EXPECT_TRUE(gpu.lastTimings().empty());  // nothing recorded, nothing timed
  EXPECT_EQ(gpu.pagesRelitLastUpdate(), 0u);
  EXPECT_EQ(gpu.downloadRadiance(), before);

  // Brighter sun, relight every fourth page only.
  lights[0].colorIntensity.w *= 2.0f;
  std::vector<std::uint32_t> subset;
  for (std::size_t i = 0; i < pages.size(); i += 4) subset.push_back(pages[i]);
  gpu.update(gpuScene, lights, {}, subset, 0.25);
  const std::vector<std::uint32_t> after = gpu.downloadRadiance();
  std::vector<bool> inSubset(before.size(), false);
  for (std::uint32_t page : subset) {
    const std::uint32_t slot = scene.image.pageTables[page] & gpu_shared::kPagePayloadMask;
    for (std::uint32_t c = 0; c < gpu_shared::kBrickMaterialCount; ++c)
      inSubset[slot * gpu_shared::kBrickMaterialCount + c] = true;
  }
  std::size_t changed = 0;
  for (std::size_t i = 0; i < before.size(); ++i) {
    if (!inSubset[i]) {
      ASSERT_EQ(after[i], before[i]) << "word " << i << " outside the subset";
    }
    changed += after[i] != before[i];
  }
  EXPECT_GT(changed, 1000u);
  // And the subset's words are what a full relight with the new lights gives (CPU reference).
  LightCacheCpu cpu;
  cpu.update(scene.image, lights, {}, subset, 0.25);
  std::vector<std::uint32_t> subsetGpu, subsetCpu;
  for (std::size_t i = 0; i < after.size(); ++i)
    if (inSubset[i]) {
      subsetGpu.push_back(after[i]);
      subsetCpu.push_back(cpu.radiance()[i]);
    }
  const Difference d = compare(subsetGpu, subsetCpu);
  EXPECT_LE(d.differing, subsetGpu.size() / 1000);
  EXPECT_LE(d.maxRelative, 0.01f);
}

TEST_F(LightGpuTest, EmissionPassesThroughWithoutLights) {
  const std::uint32_t glow = gpu_shared::packRgb9e5({2.5f, 0.75f, 0.1f});
  AnalyticScene scene(
      [](glm::vec3 p) {
        return test::sdBox(p, {60, 20, 60}, {62, 100, 100});
      },
      test::rgba8(255, 255, 255), glow, 0.5);
  GpuStackScene gpuScene(ctx());
  gpuScene.uploadAll(scene.image);
  LightCache gpu(ctx());
  gpu.update(gpuScene, {}, {}, scene.residentPages(), 0.5);
  const std::vector<std::uint32_t> got = gpu.downloadRadiance();
  ASSERT_EQ(got.size(), scene.emission.size());
  for (std::size_t i = 0; i < got.size(); ++i) ASSERT_EQ(got[i], glow) << "word " << i;
  LightCacheCpu cpu;
  cpu.update(scene.image, {}, {}, scene.residentPages(), 0.5);
  EXPECT_TRUE(std::equal(got.begin(), got.end(), cpu.radiance().begin()));
}

TEST_F(LightGpuTest, AtlasGrowthKeepsLitSlotsAndZeroesNewOnes) {
  AnalyticScene small(test::sdFloor, test::rgba8(200, 200, 200));
  GpuStackScene gpuScene(ctx());
  gpuScene.uploadAll(small.image);
  LightCache gpu(ctx());
  const std::vector<gpu_shared::GpuLight> lights{test::sunLight({0, 1, 0}, 1.0f)};
  const std::vector<std::uint32_t> pages = small.residentPagesIn({7, 5, 7}, {7, 5, 7});
  gpu.update(gpuScene, lights, {}, pages, 1.0);
  const std::vector<std::uint32_t> first = gpu.downloadRadiance();
  ASSERT_EQ(first.size(), small.albedo.size());

  AnalyticScene bigger(sdMixed, mixedAlbedo, mixedEmission, 1.0);  // more slots
  ASSERT_GT(bigger.albedo.size(), small.albedo.size());
  gpuScene.uploadAll(bigger.image);
  gpu.update(gpuScene, lights, {}, {}, 1.0);  // grows, relights nothing
  const std::vector<std::uint32_t> grown = gpu.downloadRadiance();
  ASSERT_EQ(grown.size(), bigger.albedo.size());
  EXPECT_TRUE(std::equal(first.begin(), first.end(), grown.begin()));
  EXPECT_TRUE(
      std::all_of(grown.begin() + first.size(), grown.end(), [](auto w) { return w == 0u; }));
}

}  // namespace
}  // namespace sdfstream
