// The light cache's direct light against closed forms on an open floor (CPU reference; the GPU
// pass is checked against it in light_gpu_test.cpp): Lambertian radiance albedo/π · E with
// E = I cosθ for a sun, I cosθ / d² for a point light, and a spot's cone window. Tolerance 1%:
// RGB9E5 keeps 9 mantissa bits of the largest channel (<= 0.2% error); the rest is float math.
#include <cmath>

#include <gtest/gtest.h>

#include "gi/light_cache.h"
#include "tests/lights/light_scenes.h"

namespace sdfstream {
namespace {
using test::AnalyticScene;
constexpr float kPi = 3.14159265358979f;
constexpr float kTolerance = 0.01f;  // relative, per channel

const std::uint32_t kAlbedo = test::rgba8(200, 150, 100);

// Relights the floor pages around x in [40, 88), z in [56, 72) (y pages 3..5).
LightCacheCpu lightFloor(const AnalyticScene& scene, std::vector<gpu_shared::GpuLight> lights,
                         double voxelSize0) {
  LightCacheCpu cache;
  cache.update(scene.image, lights, gpu_shared::GpuSky{},
               scene.residentPagesIn({5, 3, 7}, {10, 5, 8}), voxelSize0);
  return cache;
}

void expectNearRelative(glm::vec3 got, glm::vec3 want, const char* what, int x) {
  for (int c = 0; c < 3; ++c)
    EXPECT_NEAR(got[c], want[c], kTolerance * want[c] + 1e-7f) << what << " x=" << x << " ch=" << c;
}

TEST(LightAnalytic, SunOnFloorIsAlbedoOverPiTimesIrradianceCosine) {
  AnalyticScene scene(test::sdFloor, kAlbedo);
  const glm::vec3 rho = test::linearAlbedo(kAlbedo);
  for (float degrees : {0.0f, 30.0f, 60.0f, 80.0f}) {
    const float theta = degrees * kPi / 180.0f;
    // Default soft-shadow sharpness: the floor must not shadow itself, even at 10° elevation.
    const LightCacheCpu cache = lightFloor(
        scene,
        {test::sunLight({std::sin(theta), std::cos(theta), 0.3f * std::sin(theta)}, 3.0f, 16.0f)},
        1.0);
    const glm::vec3 l =
        glm::normalize(glm::vec3(std::sin(theta), std::cos(theta), 0.3f * std::sin(theta)));
    const glm::vec3 want = rho / kPi * 3.0f * l.y;
    // The four cell rows whose centres lie within 1.5 voxels of the top (y = 38.5 .. 41.5) all
    // project onto the floor; the row above (42.5) is not a surface cell.
    for (int x = 44; x < 84; x += 3)
      for (int y = 38; y <= 41; ++y) {
        const glm::vec3 got = test::decode(cache.radiance()[scene.materialIndex({x, y, 64})]);
        expectNearRelative(got, want, "sun", x);
      }
    EXPECT_EQ(cache.radiance()[scene.materialIndex({60, 42, 64})], 0u);
  }
}

TEST(LightAnalytic, PointLightFallsOffWithDistanceSquaredInMetres) {
  AnalyticScene scene(test::sdFloor, kAlbedo);
  const glm::vec3 rho = test::linearAlbedo(kAlbedo);
  const double voxel = 0.1;  // metres: the light 10 voxels up is 1 m away
  const glm::vec3 light(64.5f, test::kFloorTop + 10.0f, 64.5f);
  const LightCacheCpu cache = lightFloor(scene, {test::pointLight(light, 2.0f)}, voxel);
  float previous = 1e30f;
  for (int x = 64; x < 88; ++x) {
    const glm::vec3 p(x + 0.5f, test::kFloorTop, 64.5f);  // surface point under the cell
    const float d = glm::length(light - p);
    const float dm = d * float(voxel);
    const glm::vec3 want = rho / kPi * 2.0f * ((light.y - p.y) / d) / (dm * dm);
    const glm::vec3 got = test::decode(cache.radiance()[scene.materialIndex({x, 40, 64})]);
    expectNearRelative(got, want, "point", x);
    EXPECT_LT(got.x, previous);
    previous = got.x;
  }
  // Right under the light (10 voxels = 1 m): E = I / (1 m)² = 2.
  const glm::vec3 under = test::decode(cache.radiance()[scene.materialIndex({64, 40, 64})]);
  expectNearRelative(under, rho / kPi * 2.0f, "under", 64);
}

TEST(LightAnalytic, PointLightRangeWindowReachesZeroAtTheRange) {
  AnalyticScene scene(test::sdFloor, kAlbedo);
  const glm::vec3 rho = test::linearAlbedo(kAlbedo);
  const double voxel = 0.1;
  const float range = 2.0f;  // metres = 20 voxels
  const glm::vec3 light(64.5f, test::kFloorTop + 10.0f, 64.5f);
  const LightCacheCpu cache = lightFloor(scene, {test::pointLight(light, 2.0f, range)}, voxel);
  for (int x = 64; x < 88; ++x) {
    const glm::vec3 p(x + 0.5f, test::kFloorTop, 64.5f);
    const float d = glm::length(light - p), dm = d * float(voxel);
    const float w = std::max(0.0f, 1.0f - std::pow(dm / range, 4.0f));
    const glm::vec3 want = rho / kPi * 2.0f * ((light.y - p.y) / d) / (dm * dm) * w * w;
    const std::uint32_t word = cache.radiance()[scene.materialIndex({x, 40, 64})];
    if (dm >= range) {
      EXPECT_EQ(word, 0u) << "x=" << x;
    } else if (w * w > 0.05f) {  // near the range the value is tiny and RGB9E5 rounds coarsely
      expectNearRelative(test::decode(word), want, "range", x);
    }
  }
}

TEST(LightAnalytic, SpotIsFullInsideInnerConeAndZeroOutsideOuterCone) {
  AnalyticScene scene(test::sdFloor, kAlbedo);
  const glm::vec3 rho = test::linearAlbedo(kAlbedo);
  const float h = 20.0f;
  const glm::vec3 light(64.5f, test::kFloorTop + h, 64.5f);
  const LightCacheCpu cache =
      lightFloor(scene, {test::spotLight(light, {0, -1, 0}, 20.0f, 30.0f, 50.0f)}, 0.1);
  int inside = 0, outside = 0, between = 0;
  for (int x = 64; x < 88; ++x) {
    const glm::vec3 p(x + 0.5f, test::kFloorTop, 64.5f);
    const float d = glm::length(light - p), dm = d * 0.1f;
    const float angle = std::acos(h / d) * 180.0f / kPi;
    const glm::vec3 full = rho / kPi * 50.0f * (h / d) / (dm * dm);
    const std::uint32_t word = cache.radiance()[scene.materialIndex({x, 40, 64})];
    if (angle < 20.0f) {
      expectNearRelative(test::decode(word), full, "spot inner", x);
      ++inside;
    } else if (angle > 30.0f) {
      EXPECT_EQ(word, 0u) << "x=" << x << " angle=" << angle;
      ++outside;
    } else {
      const glm::vec3 got = test::decode(word);
      EXPECT_GT(got.x, 0.0f) << "x=" << x;
      EXPECT_LT(got.x, full.x) << "x=" << x;
      ++between;
    }
  }
  EXPECT_GT(inside, 3);
  EXPECT_GT(outside, 3);
  EXPECT_GT(between, 1);
}

TEST(LightAnalytic, CellsAwayFromTheSurfaceKeepOnlyTheirEmission) {
  const std::uint32_t glow = gpu_shared::packRgb9e5(glm::vec3(0.5f, 0.25f, 2.0f));
  AnalyticScene scene(test::sdFloor, kAlbedo, glow);
  const LightCacheCpu cache = lightFloor(scene, {test::sunLight({0, 1, 0}, 3.0f)}, 1.0);
  for (int y : {24, 26, 28, 34, 36, 42, 44, 46}) {  // |d| > 1.5: inside the slab or in the air
    EXPECT_EQ(cache.radiance()[scene.materialIndex({60, y, 60})], glow) << "y=" << y;
  }
  // Surface cells add the sun to the emission.
  const glm::vec3 top = test::decode(cache.radiance()[scene.materialIndex({60, 40, 60})]);
  EXPECT_GT(top.x, 0.5f + 0.5f * test::linearAlbedo(kAlbedo).x / kPi * 3.0f);
}

TEST(LightAnalytic, SkyIsHorizonBelowAndZenithStraightUp) {
  // skyRadiance is shared GLSL/C++ math; the probes call it for rays that leave the stack.
  AnalyticScene scene(test::sdFloor, kAlbedo);
  gpu_shared::GpuSky sky{};
  sky.zenith = glm::vec4(0.2f, 0.4f, 1.0f, 0.0f);
  sky.horizon = glm::vec4(1.0f, 0.9f, 0.8f, 0.0f);
  EXPECT_EQ(skyRadianceCpu(sky, {0, 1, 0}), glm::vec3(sky.zenith));
  EXPECT_EQ(skyRadianceCpu(sky, {1, 0, 0}), glm::vec3(sky.horizon));
  EXPECT_EQ(skyRadianceCpu(sky, glm::normalize(glm::vec3(1, -1, 0))), glm::vec3(sky.horizon));
  const glm::vec3 mid = skyRadianceCpu(sky, glm::normalize(glm::vec3(1, 1, 0)));
  const float s = std::sqrt(0.5f);
  EXPECT_NEAR(mid.x, 1.0f + (0.2f - 1.0f) * s, 1e-6f);
  EXPECT_NEAR(mid.z, 0.8f + (1.0f - 0.8f) * s, 1e-6f);
}

// The full relight's work census (lightCacheWork) against the same cells taken one by one
// (lightCellSteps, the diagnosis path): surface cells, the shadow rays of those facing the sun,
// and which of them are blocked; the warp-step counts can only be at or above their floor.
TEST(LightCacheWork, CountsTheCellsAndRaysOfEveryResidentPage) {
  const AnalyticScene scene(
      [](glm::vec3 p) {
        return std::min(test::sdFloor(p), test::sdBox(p, {56, 40, 56}, {72, 60, 72}));
      },
      kAlbedo);
  // Hard shadows: a march's visibility is 0 exactly when it is blocked.
  const gpu_shared::GpuLight sun = test::sunLight({0.5f, 0.7f, 0.3f}, 2.0f);
  const std::vector<gpu_shared::GpuLight> lights = {sun};
  const LightCacheWork work = lightCacheWork(scene.image, lights);
  std::uint64_t surface = 0, rays = 0, blocked = 0;
  const std::vector<std::uint32_t> pages = scene.residentPages();
  for (std::uint32_t global : pages)
    for (std::uint32_t cell = 0; cell < gpu_shared::kBrickMaterialCount; ++cell) {
      const glm::ivec3 page(int(global % 16), int(global / 16 % 16), int(global / 256));
      const glm::vec3 centre = glm::vec3(page * 8) + AnalyticScene::cellOffset(cell);
      const LightCellSteps st = lightCellSteps(scene.image, sun, 0, centre);
      if (!st.inBand) continue;
      ++surface;
      if (st.cosine <= 0.0f) continue;
      ++rays;
      blocked += st.visibility <= 0.0f;
    }
  EXPECT_EQ(work.pages, pages.size());
  EXPECT_EQ(work.surfaceCells, surface);
  EXPECT_EQ(work.shadowRays, rays);
  EXPECT_EQ(work.blockedRays, blocked);
  EXPECT_GT(blocked, 100u);          // the box shadows part of the floor
  EXPECT_GT(rays - blocked, 1000u);  // and the sun reaches the rest
  ASSERT_EQ(work.stepsByCascade.size(), 1u);
  EXPECT_EQ(work.stepsByCascade[0], work.steps);
  EXPECT_GE(work.steps, work.shadowRays);
  EXPECT_EQ(work.warpStepsFloor, (work.steps + 31) / 32);
  EXPECT_GE(work.warpStepsOneList, work.warpStepsFloor);
  EXPECT_GE(work.warpStepsPerPage, work.warpStepsFloor);
  EXPECT_LE(work.medianCellSteps, work.p99CellSteps);
  EXPECT_LE(work.p99CellSteps, work.maxCellSteps);
}
}  // namespace
}  // namespace sdfstream
