// Which pages the light cache relights (lightDirtyPages), and the shared RGB9E5 encoder the light
// cache shader writes with (shaders/shared/color_codec.h) against an independent implementation.
#include <algorithm>
#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "gi/light_cache.h"
#include "tests/lights/light_scenes.h"

namespace sdfstream {
namespace {
using test::AnalyticScene;

float sdFloorAndPost(glm::vec3 p) {
  return std::min(test::sdFloor(p), test::sdBox(p, {60, 40, 60}, {68, 70, 68}));
}

TEST(LightDirtyPages, EverythingResidentWhenLightsChangedOrNothingToCompare) {
  AnalyticScene scene(sdFloorAndPost, test::rgba8(128, 128, 128));
  const std::vector<std::uint32_t> all = scene.residentPages();
  ASSERT_GT(all.size(), 700u);
  EXPECT_EQ(lightDirtyPages(nullptr, scene.image, false), all);
  EXPECT_EQ(lightDirtyPages(&scene.image, scene.image, true), all);
  EXPECT_TRUE(lightDirtyPages(&scene.image, scene.image, false).empty());
  CascadeStackImage twoCascades = scene.image;
  twoCascades.pageTables.resize(2 * gpu_shared::kCascadePageCount, 0u);
  twoCascades.params.push_back(twoCascades.params[0]);
  twoCascades.params[1].offsetScale = glm::vec4(-64.0f, -64.0f, -64.0f, 2.0f);
  twoCascades.params[1].toroidal.w = gpu_shared::kCascadePageCount;
  EXPECT_EQ(lightDirtyPages(&twoCascades, scene.image, false), all);  // cascade count changed
}

TEST(LightDirtyPages, ExactlyTheChangedResidentPages) {
  AnalyticScene scene(sdFloorAndPost, test::rgba8(128, 128, 128));
  CascadeStackImage next = scene.image;
  const std::vector<std::uint32_t> resident = scene.residentPages();
  const std::uint32_t moved = resident[10], evicted = resident[20];
  next.pageTables[moved] = gpu_shared::kPageResidentBit | 9999u;  // new brick in another slot
  next.pageTables[evicted] = gpu_shared::kPageMissing;            // no longer resident
  std::uint32_t streamedIn = 0;  // an empty page that now holds a brick
  while (next.pageTables[streamedIn] & gpu_shared::kPageResidentBit) ++streamedIn;
  next.pageTables[streamedIn] = gpu_shared::kPageResidentBit | 10000u;
  std::uint32_t boundChanged = streamedIn + 1;  // an empty page whose bound changed: no light
  while (next.pageTables[boundChanged] & gpu_shared::kPageResidentBit) ++boundChanged;
  next.pageTables[boundChanged] += 1;
  std::vector<std::uint32_t> want{moved, streamedIn};
  std::sort(want.begin(), want.end());
  EXPECT_EQ(lightDirtyPages(&scene.image, next, false), want);
}

TEST(LightDirtyPages, ScrollingMarksTheEnteringSlabEvenWhenItsEntryValueIsReused) {
  // Cascade 0 moves one page (8 voxels) in +x: toroidal entry i now holds the brick one page
  // further on, so only the entries that wrapped around (the entering slab, page x = 15) hold a
  // new brick -- here with the very same slot numbers, as a LIFO free list would hand out.
  AnalyticScene scene(sdFloorAndPost, test::rgba8(128, 128, 128));
  CascadeStackImage next = scene.image;
  next.cascade0MinWorld.x += 8.0 * next.voxelSize0;
  next.params[0].toroidal.x = 1;
  std::vector<std::uint32_t> want;
  for (std::uint32_t i = 0; i < gpu_shared::kCascadePageCount; ++i)
    if ((next.pageTables[i] & gpu_shared::kPageResidentBit) && (i & 15u) == 0u) want.push_back(i);
  ASSERT_FALSE(want.empty());
  EXPECT_EQ(lightDirtyPages(&scene.image, next, false), want);
}

// EXT_texture_shared_exponent's encoder, written independently with frexp/floor (the encoder
// world/color_pack.h had before it forwarded to the shared one).
std::uint32_t referenceRgb9e5(glm::vec3 rgb) {
  const float maxValue = 511.0f / 512.0f * 65536.0f;
  auto clampChannel = [&](float v) { return v > 0.0f ? std::min(v, maxValue) : 0.0f; };
  const float r = clampChannel(rgb.r), g = clampChannel(rgb.g), b = clampChannel(rgb.b);
  const float maxc = std::max(r, std::max(g, b));
  if (maxc <= 0.0f) return 0;
  int e2;
  std::frexp(maxc, &e2);
  int shared = std::max(-16, e2 - 1) + 16;
  float scale = std::ldexp(1.0f, -(shared - 24));
  if (int(std::floor(maxc * scale + 0.5f)) == 512) {
    ++shared;
    scale *= 0.5f;
  }
  shared = std::min(shared, 31);
  auto mant = [&](float v) {
    return std::uint32_t(std::min(511.0f, std::floor(v * scale + 0.5f)));
  };
  return mant(r) | mant(g) << 9 | mant(b) << 18 | std::uint32_t(shared) << 27;
}

TEST(LightRgb9e5, SharedEncoderMatchesReferenceBitForBit) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> logu(-30.0f, 17.0f);
  std::uniform_int_distribution<int> pick(0, 9);
  for (int i = 0; i < 200000; ++i) {
    glm::vec3 c(std::exp2(logu(rng)), std::exp2(logu(rng)), std::exp2(logu(rng)));
    if (pick(rng) == 0) c.y = 0.0f;
    if (pick(rng) == 0) c.z = -c.z;
    ASSERT_EQ(gpu_shared::packRgb9e5(c), referenceRgb9e5(c)) << c.x << " " << c.y << " " << c.z;
  }
  for (float v : {0.0f, 1e-45f, 1e-38f, 1.0f / 65536.0f, 0.5f, 1.0f, 511.0f / 256.0f, 2.0f,
                  65408.0f, 65535.0f, 1e9f, INFINITY, -1.0f, NAN}) {
    EXPECT_EQ(gpu_shared::packRgb9e5(glm::vec3(v)), referenceRgb9e5(glm::vec3(v))) << v;
    EXPECT_EQ(gpu_shared::packRgb9e5(glm::vec3(v, 0.25f, 0.0f)),
              referenceRgb9e5(glm::vec3(v, 0.25f, 0.0f)))
        << v;
  }
  // Canonical encodings survive a decode/encode round trip unchanged.
  for (std::uint32_t word :
       {0x80000000u | 300u | 200u << 9, 0x78000000u | 511u, 0x08000000u | 256u})
    EXPECT_EQ(gpu_shared::packRgb9e5(gpu_shared::unpackRgb9e5(word)), word);
}

}  // namespace
}  // namespace sdfstream
