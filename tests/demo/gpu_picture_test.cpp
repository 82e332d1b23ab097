// The GPU-composed picture (GiRenderer::renderPicture: rays, shading, per-pixel probe sampling
// through the installable include, tone map, all on the device) against the host path it
// replaces (shade → probeQueries → GiSystem::irradiance → composeFrame → toneMap), on the
// demo_gi scene with GI on: every view mode, with the SDF and the raster primary.
#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>
#include <map>

#include "demo/frame_image.h"
#include "demo/gi_shading.h"
#include "tests/demo/demo_gi_scene.h"
#include "tests/support/gpu_test.h"

namespace sdfstream {
namespace {

class GpuPictureTest : public test::GpuTest {};

// Values off by more than one level (rounding at a boundary, float order of the two paths), and
// the largest difference.
struct Difference {
  std::size_t offByMore = 0;
  int largest = 0;
};
Difference compare(const Image8& a, const Image8& b) {
  Difference d;
  for (std::size_t i = 0; i < a.rgb.size(); ++i) {
    const int diff = std::abs(int(a.rgb[i]) - int(b.rgb[i]));
    d.largest = std::max(d.largest, diff);
    d.offByMore += diff > 1 ? 1 : 0;
  }
  return d;
}

// The host path's picture of each mode (viewer/view_picture.cpp's rules).
Image8 hostPicture(std::uint32_t mode, const ShadedView& view, const HdrFrame& frame) {
  const int w = frame.width, h = frame.height;
  if (mode == gpu_shared::kFrameFinal) return toneMap(frame.final(), w, h, 0.0f);
  if (mode == gpu_shared::kFrameDirect) return toneMap(frame.direct, w, h, 0.0f);
  if (mode == gpu_shared::kFrameIndirect) return toneMap(frame.indirect, w, h, 2.0f);
  Image8 out{w, h, std::vector<std::uint8_t>(std::size_t(w) * h * 3, 0)};
  for (std::size_t p = 0; p < view.shaded.size(); ++p) {
    const gpu_shared::ShadedHit& hit = view.shaded[p];
    if (!(hit.flags & gpu_shared::kHitFlagHit)) continue;
    if (mode == gpu_shared::kFrameAlbedo) {
      for (int c = 0; c < 3; ++c) out.rgb[3 * p + c] = (hit.albedo >> (8 * c)) & 255u;
    } else if (mode == gpu_shared::kFrameResidency) {
      const bool fellBack = hit.flags & gpu_shared::kHitFlagFellBack;
      const std::uint8_t c[3] = {std::uint8_t(fellBack ? 240 : 80),
                                 std::uint8_t(fellBack ? 140 : 200),
                                 std::uint8_t(fellBack ? 30 : 80)};
      for (int k = 0; k < 3; ++k) out.rgb[3 * p + k] = c[k];
    } else if (mode == gpu_shared::kFrameNormals) {
      const glm::vec3 n = glm::clamp(glm::vec3(hit.normalT) * 0.5f + 0.5f, 0.0f, 1.0f);
      for (int c = 0; c < 3; ++c) out.rgb[3 * p + c] = std::uint8_t(n[c] * 255.0f + 0.5f);
    }
  }
  return out;
}

TEST_F(GpuPictureTest, MatchesTheHostPathInEveryMode) {
  const TriangleScene triangles = test::demoGiTriangles();
  const World world = meshToWorld(triangles, 0.0, ImportLimits{});
  const CascadeImage cascade = buildCascade(world, cascadeOriginForWorld(world));
  const CascadeStackImage image = stackImageOf(cascade);
  const SceneLights lights = test::demoGiLights();
  const Camera camera = test::demoGiCamera();
  constexpr int kW = 96, kH = 72;
  const auto renderer = test::demoGiRenderer(ctx(), image, lights, camera, 8);
  GiRenderer& gi = *renderer;

  for (bool raster : {false, true}) {
    gi.setPrimaryMesh(raster ? &triangles : nullptr);
    const ShadedView view = gi.shade(camera, kW, kH, image, lights);
    const HdrFrame frame = gi.finish(view);
    ASSERT_GT(frame.hits, std::size_t(kW * kH / 2));
    for (std::uint32_t mode :
         {gpu_shared::kFrameFinal, gpu_shared::kFrameDirect, gpu_shared::kFrameIndirect,
          gpu_shared::kFrameAlbedo, gpu_shared::kFrameNormals, gpu_shared::kFrameResidency}) {
      PictureSettings settings;
      settings.mode = mode;
      const Image8 gpu = gi.renderPicture(camera, kW, kH, image, lights, settings);
      const Image8 host = hostPicture(mode, view, frame);
      ASSERT_EQ(gpu.rgb.size(), host.rgb.size());
      const Difference d = compare(gpu, host);
      std::printf("%s primary, mode %u: %zu of %zu values off by more than 1 (largest %d)\n",
                  raster ? "raster" : "SDF", mode, d.offByMore, gpu.rgb.size(), d.largest);
      // Rays made on the GPU in float (the host's in double) may tip a silhouette pixel.
      EXPECT_LE(d.offByMore, gpu.rgb.size() / 500) << "mode " << mode;
    }
    // Probe states: every hit pixel shows one of the four state colours.
    PictureSettings states;
    states.mode = gpu_shared::kFrameProbeStates;
    const Image8 stateImage = gi.renderPicture(camera, kW, kH, image, lights, states);
    const glm::u8vec3 palette[4] = {{80, 80, 80}, {60, 160, 230}, {80, 200, 80}, {230, 60, 60}};
    std::size_t counted[4] = {}, other = 0;
    for (std::size_t p = 0; p < view.shaded.size(); ++p) {
      if (!(view.shaded[p].flags & gpu_shared::kHitFlagHit)) continue;
      const glm::u8vec3 c(stateImage.rgb[3 * p], stateImage.rgb[3 * p + 1],
                          stateImage.rgb[3 * p + 2]);
      int k = 0;
      while (k < 4 && palette[k] != c) ++k;
      if (k < 4)
        ++counted[k];
      else
        ++other;
    }
    std::printf(
        "probe states over hit pixels: off %zu, sleeping %zu, awake %zu, vigilant %zu, "
        "other %zu\n",
        counted[0], counted[1], counted[2], counted[3], other);
    EXPECT_LE(other, frame.hits / 100);  // hits outside every volume: black
    EXPECT_GT(counted[1] + counted[2] + counted[3], frame.hits / 2);
    // The G key: the final picture without the indirect light is the direct picture.
    PictureSettings noIndirect;
    noIndirect.indirect = false;
    const Difference d = compare(gi.renderPicture(camera, kW, kH, image, lights, noIndirect),
                                 toneMap(frame.direct, kW, kH, 0.0f));
    EXPECT_LE(d.offByMore, std::size_t(kW * kH * 3 / 500));
  }
}

// The object-regions view with two objects over the floor: their own pixels white, the floor
// pixels under and around them in regions that list them (yellow: one object), the rest of the
// scene in regions that list none (dark grey); with no objects, every hit is dark grey.
TEST_F(GpuPictureTest, ObjectRegionsShowWhereObjectsAreListed) {
  const World world = test::demoGiWorld();
  const CascadeImage cascade = buildCascade(world, cascadeOriginForWorld(world));
  const CascadeStackImage image = stackImageOf(cascade);
  const SceneLights lights = test::demoGiLights();
  const Camera camera = test::demoGiCamera();
  constexpr int kW = 96, kH = 72;
  ObjectLibrary library(ObjectSdfSettings{16, 24, 0.0, 2});
  const std::uint32_t box = library.addBox({0.3f, 0.2f, 0.25f}, {0.9f, 0.5f, 0.1f, 1.0f});
  InstanceSet instances;
  for (const glm::dvec3 at : {glm::dvec3(-0.6, 0.5, 0.6), glm::dvec3(0.2, 0.4, -1.0)}) {
    ObjectTransform t;
    t.translation = at;
    instances.add(box, t);
  }
  GiRendererOptions options;
  options.settings.probes.raysPerProbe = 16;
  options.settings.probes.spacingBricks = 2;
  GiRenderer gi(ctx(), options, 1);
  PictureSettings regions;
  regions.mode = gpu_shared::kFrameObjectRegions;
  auto histogram = [&](const Image8& picture) {
    std::map<std::uint32_t, std::size_t> h;
    for (std::size_t p = 0; p < picture.rgb.size() / 3; ++p)
      ++h[picture.rgb[3 * p] | picture.rgb[3 * p + 1] << 8 | picture.rgb[3 * p + 2] << 16];
    return h;
  };
  gi.update(image, lights, {}, 0);
  auto none = histogram(gi.renderPicture(camera, kW, kH, image, lights, regions));
  gi.setObjects(&library, &instances);
  gi.update(image, lights, {}, 1);
  auto some = histogram(gi.renderPicture(camera, kW, kH, image, lights, regions));
  constexpr std::uint32_t kWhite = 0xe6e6e6, kGrey = 0x404040, kYellow = 0x3cdce6;
  std::printf("no objects: %zu grey, %zu yellow; two objects: %zu white, %zu yellow, %zu grey\n",
              none[kGrey], none[kYellow], some[kWhite], some[kYellow], some[kGrey]);
  EXPECT_GT(none[kGrey], std::size_t(kW * kH / 2));
  EXPECT_EQ(none[kYellow] + none[kWhite], 0u);
  EXPECT_GT(some[kWhite], 20u);
  EXPECT_GT(some[kYellow], 20u);
  EXPECT_GT(some[kGrey], some[kYellow]);  // most of the scene lists no object
}

}  // namespace
}  // namespace sdfstream
