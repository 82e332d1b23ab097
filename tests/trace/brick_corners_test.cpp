// The corner atlas (sdf_layout.h kBrickCornerWords: the distances regrouped by trilinear cell, so
// a GPU trace reads a sample in one load) against the same regrouping done here from the
// distance atlas: bit for bit, after a whole upload and after a per-frame sync of listed slots.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <vector>

#include <glm/gtc/packing.hpp>

#include "gi/gpu_stack_scene.h"
#include "gi/gpu_stack_tracer.h"
#include "tests/support/gpu_test.h"
#include "tests/support/streamed_bunny.h"

namespace sdfstream {
namespace {
namespace gs = gpu_shared;

std::uint32_t sampleBits(const std::vector<std::uint32_t>& atlas, std::uint32_t slot,
                         std::uint32_t x, std::uint32_t y, std::uint32_t z) {
  const std::uint32_t i = x + 9 * (y + 9 * z);
  return (atlas[std::size_t(slot) * gs::kBrickDistanceWords + i / 2] >> (16 * (i % 2))) & 0xffffu;
}

// Cell (x, y, z)'s corners as sdf_layout.h orders them: (d000, d100), (d010, d110), (d001, d101),
// (d011, d111), the first of each pair in the low half.
std::array<std::uint32_t, 4> expectedCorners(const std::vector<std::uint32_t>& atlas,
                                             std::uint32_t slot, std::uint32_t cell) {
  const std::uint32_t x = cell % 8, y = cell / 8 % 8, z = cell / 64;
  auto pair = [&](std::uint32_t dy, std::uint32_t dz) {
    return sampleBits(atlas, slot, x, y + dy, z + dz) |
           (sampleBits(atlas, slot, x + 1, y + dy, z + dz) << 16);
  };
  return {pair(0, 0), pair(1, 0), pair(0, 1), pair(1, 1)};
}

// Cells of the listed slots whose corners differ from the distance atlas's.
std::size_t differingCells(const gpu::Buffer& corners, const std::vector<std::uint32_t>& atlas,
                           const std::vector<std::uint32_t>& slots) {
  std::vector<std::uint32_t> got(corners.size() / 4);
  corners.download(got.data(), got.size() * 4);
  std::size_t differ = 0;
  for (std::uint32_t slot : slots)
    for (std::uint32_t cell = 0; cell < gs::kBrickMaterialCount; ++cell) {
      const auto want = expectedCorners(atlas, slot, cell);
      const std::size_t at = (std::size_t(slot) * gs::kBrickMaterialCount + cell) * 4;
      for (int k = 0; k < 4; ++k) differ += got[at + k] != want[k] ? 1 : 0;
    }
  return differ;
}

class BrickCorners : public test::GpuTest {};

TEST_F(BrickCorners, EqualTheDistanceAtlasRegroupedByCell) {
  test::StreamedBunny b = test::streamBunny();
  const std::vector<std::uint32_t>& atlas = b.stack->atlasDistance();
  const std::uint32_t slotCount = std::uint32_t(atlas.size() / gs::kBrickDistanceWords);
  ASSERT_GT(slotCount, 100u);
  std::vector<std::uint32_t> all(slotCount), listed;
  for (std::uint32_t s = 0; s < slotCount; ++s) all[s] = s;
  for (std::uint32_t s = 1; s < slotCount; s += 3) listed.push_back(s);
  // The surface crosses the bricks: many distances are not the band's clamp value, so a wrong
  // sample would show.
  std::size_t inBand = 0;
  for (std::uint32_t w : atlas)
    inBand += std::abs(glm::unpackHalf2x16(w).x) < 0.9f * gs::kNarrowBand ? 1 : 0;
  ASSERT_GT(inBand, atlas.size() / 20);

  GpuStackScene whole(ctx());
  whole.uploadAll(b.stack->stackImage());
  const std::size_t wholeDiffer = differingCells(whole.corners(), atlas, all);

  GpuStackScene synced(ctx());
  synced.sync(*b.stack, listed);
  const std::size_t syncedDiffer = differingCells(synced.corners(), atlas, listed);

  std::printf(
      "[figures] corner atlas: %u slots uploaded whole, %zu words differ; %zu slots synced, %zu "
      "differ\n",
      slotCount, wholeDiffer, listed.size(), syncedDiffer);
  EXPECT_EQ(wholeDiffer, 0u);
  EXPECT_EQ(syncedDiffer, 0u);
}

// The same camera rays traced through the corner atlas and through the distance atlas: the same
// fp16 values interpolated the same way, so every hit is the same to the bit.
TEST_F(BrickCorners, TracesAreTheSameThroughEitherAtlas) {
  test::StreamedBunny b = test::streamBunny();
  const CascadeStackImage img = b.stack->stackImage();
  std::vector<std::uint32_t> all(b.stack->atlasDistance().size() / gs::kBrickDistanceWords);
  for (std::uint32_t s = 0; s < all.size(); ++s) all[s] = s;
  GpuStackTracer corners(ctx(), *b.stack, true), words(ctx(), *b.stack, false);
  corners.sync(*b.stack, all);
  words.sync(*b.stack, all);
  ASSERT_TRUE(corners.scene().cellCorners());
  ASSERT_FALSE(words.scene().cellCorners());
  ASSERT_FALSE(words.scene().corners());

  std::vector<gs::TraceRay> rays;
  const glm::vec3 from = img.toStack(b.camera);
  const glm::vec3 lo = img.toStack(glm::dvec3(b.triangles.boundsMin()));
  const glm::vec3 hi = img.toStack(glm::dvec3(b.triangles.boundsMax()));
  for (int i = 0; i < 4096; ++i) {
    const glm::vec3 f(float(i % 64) / 63.0f, float(i / 64) / 63.0f, 0.5f);
    gs::TraceRay r{};
    r.originTMin = glm::vec4(from, 0.0f);
    r.dirTMax = glm::vec4(glm::normalize(lo + (hi - lo) * f - from), 1e30f);
    rays.push_back(r);
  }
  const auto a = corners.trace(rays, TraceSettings{});
  const auto w = words.trace(rays, TraceSettings{});
  std::size_t hits = 0, differ = 0;
  for (std::size_t i = 0; i < rays.size(); ++i) {
    hits += (a[i].flags & gs::kHitFlagHit) ? 1 : 0;
    differ += std::memcmp(&a[i], &w[i], sizeof a[i]) != 0 ? 1 : 0;
  }
  std::printf("[figures] %zu rays, %zu hits: %zu differ between the atlases\n", rays.size(), hits,
              differ);
  EXPECT_GT(hits, rays.size() / 4);
  EXPECT_EQ(differ, 0u);
}

// An atlas whose corners the device cannot bind whole (maxStorageBufferRange) traces through the
// distance atlas instead.
TEST_F(BrickCorners, AnAtlasTooLargeToBindTracesThroughTheDistances) {
  const std::uint64_t range = ctx().properties().limits.maxStorageBufferRange;
  const std::uint64_t fit = range / (gs::kBrickCornerWords * 4);
  if (fit > 32768) GTEST_SKIP() << "this device binds " << fit << " slots of corners";
  GpuStackScene fits(ctx()), tooLarge(ctx());
  fits.reserveAtlas(std::uint32_t(fit));
  tooLarge.reserveAtlas(std::uint32_t(fit + 1));
  EXPECT_TRUE(fits.cellCorners());
  EXPECT_EQ(&fits.traceAtlas(), &fits.corners());
  EXPECT_FALSE(tooLarge.cellCorners());
  EXPECT_EQ(&tooLarge.traceAtlas(), &tooLarge.distance());
}

}  // namespace
}  // namespace sdfstream
