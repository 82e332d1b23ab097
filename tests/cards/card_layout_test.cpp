#include "cards/card_layout.h"

#include <stdexcept>

#include <gtest/gtest.h>

namespace sdfstream {
namespace {

using gpu_shared::CardGpu;

TEST(CardLayout, SixFacesSizedByTheVoxelAndNumberedCardByCard) {
  const MeshCards m = layoutCards({0, 0, 0}, {2.0f, 1.0f, 0.5f}, 0.1f);
  // Card k: axis k / 2, u = (axis + 1) % 3, v = (axis + 2) % 3, one texel per voxel.
  const glm::uvec2 expected[3] = {{10, 5}, {5, 20}, {20, 10}};
  std::uint32_t first = 0;
  for (std::uint32_t k = 0; k < 6; ++k) {
    const CardGpu& c = m.cards[k];
    EXPECT_EQ(c.info.x, k / 2);
    EXPECT_EQ(c.info.y, k % 2);
    EXPECT_EQ(c.info.z, expected[k / 2].x) << k;
    EXPECT_EQ(c.info.w, expected[k / 2].y) << k;
    EXPECT_EQ(c.first.x, first);
    first += c.info.z * c.info.w;
    EXPECT_NEAR(c.texel.x, 0.1f, 1e-6f);
    EXPECT_NEAR(c.texel.y, 0.1f, 1e-6f);
  }
  EXPECT_EQ(m.texelCount, first);
  EXPECT_EQ(m.texelCount, 2u * (50 + 100 + 200));
  // The + face's plane lies depthPad × the longest extent outside the box, looking inwards.
  EXPECT_NEAR(m.cards[0].plane.z, 2.0f + 0.02f, 1e-6f);
  EXPECT_NEAR(m.cards[1].plane.z, -0.02f, 1e-6f);
  EXPECT_EQ(cardViewDirection(m.cards[0]), glm::vec3(-1, 0, 0));
  EXPECT_EQ(cardViewDirection(m.cards[5]), glm::vec3(0, 0, 1));
  EXPECT_NEAR(cardDepthOf(m.cards[0], {2.0f, 0.3f, 0.1f}), 0.02f, 1e-6f);
  EXPECT_NEAR(cardDepthOf(m.cards[1], {2.0f, 0.3f, 0.1f}), 2.02f, 1e-6f);
}

// Light levels: card (10 x 5) has 5 x 3 light texels at level 1 and 3 x 2 at level 2 (rounded
// up), each card's first light texel at a level the sum of the cards before it at that level, and
// the light index of card texel (i, j) the light texel covering it.
TEST(CardLayout, LightLevelsHalveEachCardRoundingUp) {
  const MeshCards m = layoutCards({0, 0, 0}, {2.0f, 1.0f, 0.5f}, 0.1f);
  // Cards 10x5, 10x5, 5x20, 5x20, 20x10, 20x10.
  EXPECT_EQ(m.lightTexels[0], m.texelCount);
  EXPECT_EQ(m.lightTexels[1], 2u * (5 * 3 + 3 * 10 + 10 * 5));
  EXPECT_EQ(m.lightTexels[2], 2u * (3 * 2 + 2 * 5 + 5 * 3));
  std::uint32_t first1 = 0, first2 = 0;
  for (std::uint32_t k = 0; k < 6; ++k) {
    const CardGpu& c = m.cards[k];
    EXPECT_EQ(gpu_shared::cardLightFirst(c, 0), c.first.x);
    EXPECT_EQ(gpu_shared::cardLightFirst(c, 1), first1) << k;
    EXPECT_EQ(gpu_shared::cardLightFirst(c, 2), first2) << k;
    first1 += gpu_shared::cardLightSize(c, 1).x * gpu_shared::cardLightSize(c, 1).y;
    first2 += gpu_shared::cardLightSize(c, 2).x * gpu_shared::cardLightSize(c, 2).y;
  }
  const CardGpu& c = m.cards[0];
  EXPECT_EQ(gpu_shared::cardLightSize(c, 1).x, 5u);
  EXPECT_EQ(gpu_shared::cardLightSize(c, 2).y, 2u);
  EXPECT_EQ(gpu_shared::cardLightIndex(c, 0, 9, 4), 9u + 10u * 4u);
  EXPECT_EQ(gpu_shared::cardLightIndex(c, 1, 9, 4), c.first.z + 4u + 5u * 2u);
  EXPECT_EQ(gpu_shared::cardLightIndex(c, 2, 9, 4), c.first.w + 2u + 3u * 1u);
}

TEST(CardLayout, TexelCountsAreClampedAndFlatBoxesGetAVoxelOfDepth) {
  CardSettings s;
  s.minTexels = 4;
  s.maxTexels = 8;
  const MeshCards m = layoutCards({0, 0, 0}, {2.0f, 0.0f, 0.05f}, 0.1f, s);
  // x: 20 texels wanted, 8 given (the texel stretches); y: flat, grown to one voxel -> 1 -> 4.
  EXPECT_EQ(m.cards[4].info.z, 8u);  // card 4: u = x
  EXPECT_NEAR(m.cards[4].texel.x, 0.25f, 1e-6f);
  EXPECT_EQ(m.cards[4].info.w, 4u);  // v = y
  EXPECT_NEAR(m.boxMax.y - m.boxMin.y, 0.1f, 1e-6f);
  EXPECT_THROW(layoutCards({0, 0, 0}, {1, 1, 1}, 0.0f), std::invalid_argument);
  s.minTexels = 9;
  EXPECT_THROW(layoutCards({0, 0, 0}, {1, 1, 1}, 0.1f, s), std::invalid_argument);
}

TEST(CardLayout, ClipMapPutsTexelCentresAtPixelCentresAndDepthInRange) {
  const MeshCards m = layoutCards({-1, -0.5f, 0}, {1, 0.5f, 3}, 0.25f);
  for (const CardGpu& c : m.cards) {
    const gpu_shared::CardCapturePush push = cardClipFromObject(c);
    auto clip = [&](glm::vec3 p) {
      const glm::vec4 h(p, 1.0f);
      return glm::vec3(glm::dot(push.clipFromObject[0], h), glm::dot(push.clipFromObject[1], h),
                       glm::dot(push.clipFromObject[2], h));
    };
    for (std::uint32_t j = 0; j < c.info.w; j += 3)
      for (std::uint32_t i = 0; i < c.info.z; i += 3) {
        const glm::vec3 q = clip(cardTexelCentre(c, i, j));
        // Viewport: pixel x = (clip.x + 1) / 2 · width; its centre is i + 0.5.
        EXPECT_NEAR((q.x + 1.0f) * 0.5f * float(c.info.z), float(i) + 0.5f, 1e-4f);
        EXPECT_NEAR((q.y + 1.0f) * 0.5f * float(c.info.w), float(j) + 0.5f, 1e-4f);
        EXPECT_NEAR(q.z, 0.0f, 1e-6f);  // on the plane
      }
    // The box's far side is at depth extent − pad, inside [0, 1].
    const glm::vec3 inside = 0.5f * (m.boxMin + m.boxMax);
    const float z = clip(inside).z;
    EXPECT_GT(z, 0.0f);
    EXPECT_LT(z, 1.0f);
    EXPECT_NEAR(z * c.plane.w, cardDepthOf(c, inside), 1e-5f);
  }
}

TEST(CardLayout, NormalPackingRoundTrips) {
  const glm::vec3 normals[] = {
      {1, 0, 0}, {0, -1, 0}, {0, 0, -1}, {0.6f, 0.0f, -0.8f}, glm::normalize(glm::vec3(-1, 2, -3))};
  for (glm::vec3 n : normals) {
    const glm::vec3 back = gpu_shared::cardUnpackNormal(gpu_shared::cardPackNormal(n));
    EXPECT_GT(glm::dot(back, n), 0.99999f) << n.x << " " << n.y << " " << n.z;
  }
}

}  // namespace
}  // namespace sdfstream
