// The demo frames' GI shading (demo/gi_shading.h) on a small scene built with the layout
// importer: a white floor, a red wall on its -x side and a white pillar, lit by a sun from +x
// (travelling towards the red wall) and a black sky, so every bit of light in the pillar's shadow
// has bounced at least once.
//  - the shading pass on the GPU matches its CPU reference (same GLSL), for both direct sources;
//  - with GI the pillar's shadow, which receives no direct light (0 without GI), is lit;
//  - the red wall tints the white floor near it: the floor's red/green ratio is higher there
//    than far from the wall with GI, and the same everywhere without.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "demo/frame_image.h"
#include "demo/gi_shading.h"
#include "gi/light_cache.h"
#include "tests/demo/demo_gi_scene.h"
#include "tests/support/gpu_test.h"
#include "tests/support/streamed_bunny.h"

namespace sdfstream {
namespace {

class DemoGiTest : public test::GpuTest {};

using test::floorMean;
using test::FloorRegion;
using test::lum;

World testWorld() { return test::demoGiWorld(); }
SceneLights testLights() { return test::demoGiLights(); }
Camera testCamera() { return test::demoGiCamera(); }

std::size_t nonFinite(const std::vector<glm::vec3>& v) {
  std::size_t bad = 0;
  for (const glm::vec3& c : v)
    bad += (std::isfinite(c.r) && std::isfinite(c.g) && std::isfinite(c.b)) ? 0 : 1;
  return bad;
}

TEST_F(DemoGiTest, ShadePassMatchesCpuReference) {
  const World world = testWorld();
  const CascadeImage cascade = buildCascade(world, cascadeOriginForWorld(world));
  const CascadeStackImage image = stackImageOf(cascade);
  const SceneLights lights = testLights();
  const auto gpuLights = toGpu(lights.lights, image);
  const auto sky = toGpu(SceneSky{glm::vec3(0.2f, 0.3f, 0.6f), glm::vec3(0.5f)});

  LightCacheCpu cpuLight;
  cpuLight.update(image, gpuLights, sky, lightDirtyPages(nullptr, image, true), image.voxelSize0);

  for (std::uint32_t direct : {gpu_shared::kShadeDirectPixel, gpu_shared::kShadeDirectCache}) {
    GiRendererOptions options;
    options.gi = false;
    options.shading.direct = direct;
    GiRenderer renderer(ctx(), options, 1);
    SceneLights withSky = lights;
    withSky.sky = SceneSky{glm::vec3(0.2f, 0.3f, 0.6f), glm::vec3(0.5f)};
    renderer.update(image, withSky, {}, 0);
    const ShadedView view = renderer.shade(testCamera(), 64, 48, image, withSky);
    const auto cpu =
        shadePrimaryCpu(image, view.rays, gpuLights, sky, options.shading, cpuLight.radiance());
    ASSERT_EQ(cpu.size(), view.shaded.size());
    std::size_t hits = 0, flagMismatch = 0, valueMismatch = 0;
    for (std::size_t i = 0; i < cpu.size(); ++i) {
      const auto &g = view.shaded[i], &c = cpu[i];
      if (g.flags != c.flags) {
        ++flagMismatch;
        continue;
      }
      hits += (g.flags & gpu_shared::kHitFlagHit) ? 1 : 0;
      const glm::vec3 dg(g.direct), dc(c.direct);
      const float tol = 1e-4f + 1e-3f * std::max(glm::length(dc), glm::length(dg));
      if (glm::length(dg - dc) > tol || std::abs(g.normalT.w - c.normalT.w) > 1e-3f ||
          g.albedo != c.albedo || g.emission != c.emission)
        ++valueMismatch;
    }
    std::printf("direct source %u: %zu hits of %zu rays, %zu flag and %zu value mismatches\n",
                direct, hits, cpu.size(), flagMismatch, valueMismatch);
    EXPECT_GT(hits, cpu.size() / 2);
    // The trace and the light math are the same GLSL with `precise`: allow a pixel in a
    // thousand to round across a threshold.
    EXPECT_LE(flagMismatch + valueMismatch, cpu.size() / 1000);
  }
}

// Camera rays descend into a finer cascade where they enter its window (sdfTraceStack): from a
// camera outside cascade 0 of the streamed bunny's 3-cascade stack, the GPU pass hits where the
// CPU reference does, cascade 0 included.
TEST_F(DemoGiTest, ShadePassFromOutsideCascadeZeroMatchesCpuReference) {
  test::StreamedBunny b = test::streamBunny();
  const CascadeStackImage image = b.stack->stackImage();
  const glm::dvec3 toward = glm::normalize(b.camera - glm::dvec3(0.0, 0.1, 0.0));
  Camera camera;
  camera.position = b.camera + toward * (1.2 * 64.0 * image.voxelSize0);  // outside cascade 0
  camera.target = glm::dvec3(0.0, 0.1, 0.0);
  camera.fovYDegrees = 30.0;
  const auto rays = primaryRaysFrom(camera, 96, 64, image.toStack(camera.position));
  const SceneLights lights = testLights();
  const auto gpuLights = toGpu(lights.lights, image);
  const auto sky = toGpu(SceneSky{glm::vec3(0.2f, 0.3f, 0.6f), glm::vec3(0.5f)});
  ShadingSettings settings;
  GpuStackScene scene(ctx());
  std::vector<std::uint32_t> all(b.stack->options().atlasSlots);
  for (std::uint32_t i = 0; i < all.size(); ++i) all[i] = i;
  scene.sync(*b.stack, all);
  PrimaryShadePass pass(ctx());
  const auto gpu = pass.run(scene, nullptr, rays, gpuLights, sky, settings, image.voxelSize0);
  const auto cpu = shadePrimaryCpu(image, rays, gpuLights, sky, settings, {});
  ASSERT_EQ(gpu.size(), cpu.size());
  std::size_t inCascade0 = 0, hits = 0, mismatched = 0;
  for (std::size_t i = 0; i < cpu.size(); ++i) {
    if (gpu[i].flags != cpu[i].flags || std::abs(gpu[i].normalT.w - cpu[i].normalT.w) > 1e-3f) {
      ++mismatched;
      continue;
    }
    if (!(cpu[i].flags & gpu_shared::kHitFlagHit)) continue;
    ++hits;
    inCascade0 += ((cpu[i].flags >> gpu_shared::kHitCascadeShift) & 15) == 0 ? 1 : 0;
  }
  std::printf(
      "[figures] from outside cascade 0: %zu hits of %zu rays, %zu in cascade 0, %zu "
      "differ GPU vs CPU\n",
      hits, cpu.size(), inCascade0, mismatched);
  EXPECT_GT(inCascade0, 100u);
  EXPECT_LE(mismatched, cpu.size() / 1000);
}

TEST_F(DemoGiTest, IndirectLightFillsShadowAndRedWallTintsFloor) {
  const World world = testWorld();
  const CascadeImage cascade = buildCascade(world, cascadeOriginForWorld(world));
  const CascadeStackImage image = stackImageOf(cascade);
  const SceneLights lights = testLights();
  const Camera camera = testCamera();
  constexpr int kW = 128, kH = 96, kGiFrames = 16;

  const auto renderer = test::demoGiRenderer(ctx(), image, lights, camera, kGiFrames);
  GiRenderer& gi = *renderer;
  probe::ProbeFrameInputs inputs;
  inputs.cameraWorld = camera.position;
  inputs.viewDirection = glm::vec3(glm::normalize(camera.target - camera.position));
  const ShadedView view = gi.shade(camera, kW, kH, image, lights);
  const HdrFrame withGi = gi.finish(view);

  GiRendererOptions off;
  off.gi = false;
  GiRenderer direct(ctx(), off, 1);
  direct.update(image, lights, inputs, 0);
  const ShadedView viewOff = direct.shade(camera, kW, kH, image, lights);
  const HdrFrame withoutGi = direct.finish(viewOff);

  const auto finalOn = withGi.final(), finalOff = withoutGi.final();
  const auto out = test::scratchDir("demo-gi-images");
  writePng(out / "gi-on.png", toneMap(finalOn, kW, kH, 0.0f));
  writePng(out / "gi-off.png", toneMap(finalOff, kW, kH, 0.0f));
  writePng(out / "indirect.png", toneMap(withGi.indirect, kW, kH, 0.0f));
  std::printf("images in %s\n", out.c_str());
  EXPECT_EQ(nonFinite(finalOn), 0u);
  EXPECT_EQ(nonFinite(finalOff), 0u);
  // GI adds to the image; the direct part is the same pass either way.
  for (std::size_t i = 0; i < finalOn.size(); ++i) ASSERT_EQ(withGi.direct[i], withoutGi.direct[i]);

  // The pillar's shadow on the floor: the sun travels -x (and a little -z) from a pillar 1.4 m
  // tall, so the floor just -x of it gets no direct light.
  const FloorRegion shadow{0.25f, 0.72f, -0.2f, 0.18f};
  int nShadow = 0, nLit = 0;
  const double shadowOff = lum(floorMean(viewOff, image, finalOff, shadow, &nShadow));
  const double shadowOn = lum(floorMean(view, image, finalOn, shadow, &nShadow));
  const FloorRegion lit{-0.6f, 0.2f, 0.6f, 1.4f};
  const double litOff = lum(floorMean(viewOff, image, finalOff, lit, &nLit));
  std::printf("shadow region (%d px): luminance %.5f without GI, %.5f with GI (lit floor %.4f)\n",
              nShadow, shadowOff, shadowOn, litOff);
  ASSERT_GT(nShadow, 20);
  ASSERT_GT(nLit, 20);
  EXPECT_LT(shadowOff, 1e-4 * litOff) << "the region is meant to receive no direct light";
  EXPECT_GT(shadowOn, 0.02 * litOff) << "indirect light should fill the shadow";

  // Colour bleeding: the floor next to the red wall vs the floor far from it (both sunlit).
  const FloorRegion nearWall{-1.75f, -1.35f, -0.6f, 0.6f};
  const FloorRegion farWall{1.45f, 1.9f, 0.5f, 1.5f};
  int nNear = 0, nFar = 0;
  auto ratio = [](glm::dvec3 c) { return c.r / c.g; };
  const double nearOn = ratio(floorMean(view, image, finalOn, nearWall, &nNear));
  const double farOn = ratio(floorMean(view, image, finalOn, farWall, &nFar));
  const double nearOff = ratio(floorMean(viewOff, image, finalOff, nearWall, &nNear));
  const double farOff = ratio(floorMean(viewOff, image, finalOff, farWall, &nFar));
  std::printf(
      "floor red/green near the red wall (%d px) / far (%d px): %.4f / %.4f with GI, "
      "%.4f / %.4f without\n",
      nNear, nFar, nearOn, farOn, nearOff, farOff);
  ASSERT_GT(nNear, 20);
  ASSERT_GT(nFar, 20);
  EXPECT_NEAR(nearOff, farOff, 0.01 * farOff) << "without GI the white floor has one colour";
  EXPECT_GT(nearOn, farOn * 1.05) << "the red wall should tint the floor near it";
}

}  // namespace
}  // namespace sdfstream
