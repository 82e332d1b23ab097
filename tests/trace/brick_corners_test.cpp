// The corner atlas (sdf_layout.h kBrickCornerWords: the distances regrouped by trilinear cell, so
// a GPU trace reads a sample in one load) against the same regrouping done here from the
// distance atlas: bit for bit, after a whole upload and after a per-frame sync of listed slots.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <vector>

#include <glm/gtc/packing.hpp>

#include "gi/gpu_stack_scene.h"
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

}  // namespace
}  // namespace sdfstream
