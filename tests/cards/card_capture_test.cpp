#include "cards/card_capture.h"

#include <cmath>

#include <gtest/gtest.h>

#include "objects/primitive_meshes.h"
#include "world/color_pack.h"

namespace sdfstream {
namespace {

using gpu_shared::CardGpu;
using gpu_shared::CardTexelGpu;

TEST(CardCaptureCpu, EveryTexelOfABoxSeesItsFaceAtThePad) {
  const glm::vec4 red(0.8f, 0.1f, 0.1f, 1.0f);
  const TriangleScene box = makeBoxMesh({0.5f, 0.3f, 0.2f}, red);
  const MeshCards cards = layoutCards(box.boundsMin(), box.boundsMax(), 0.05f);
  const auto visibility = captureCardsCpu(box, cards);
  const auto texels = resolveCardTexels(box, cards, visibility);
  const float pad = 0.01f * 1.0f;  // depthPad × the longest extent (1.0)
  std::size_t checked = 0;
  for (const CardGpu& c : cards.cards)
    for (std::uint32_t k = 0; k < c.info.z * c.info.w; ++k) {
      const CardTexelGpu& t = texels[c.first.x + k];
      ASSERT_NE(visibility[c.first.x + k].triangle, 0u);
      EXPECT_NEAR(t.depth, pad, 1e-5f);
      EXPECT_EQ(t.albedo, packAlbedo(red));
      EXPECT_EQ(t.emission, 0u);
      const glm::vec3 n = gpu_shared::cardUnpackNormal(t.normal);
      EXPECT_GT(glm::dot(n, -cardViewDirection(c)), 0.9999f);
      ++checked;
    }
  EXPECT_EQ(checked, cards.texelCount);
}

TEST(CardCaptureCpu, SphereDepthFollowsTheSurfaceAndOutsideIsEmpty) {
  const float r = 1.0f;
  const TriangleScene sphere = makeSphereMesh(r, glm::vec4(0.5f), 48);
  const MeshCards cards = layoutCards(sphere.boundsMin(), sphere.boundsMax(), 0.04f);
  const auto texels = resolveCardTexels(sphere, cards, captureCardsCpu(sphere, cards));
  // Facets lie inside the sphere by at most r(1 − cos(π/48)·cos(π/48)) ≈ 0.0043 r.
  const float facet = r * (1.0f - std::cos(3.14159265f / 48) * std::cos(3.14159265f / 48));
  std::size_t inside = 0, outside = 0;
  for (const CardGpu& c : cards.cards) {
    const glm::ivec3 a = cardAxes(c);
    for (std::uint32_t j = 0; j < c.info.w; ++j)
      for (std::uint32_t i = 0; i < c.info.z; ++i) {
        const glm::vec3 p = cardTexelCentre(c, i, j);
        const float rr = p[a.x] * p[a.x] + p[a.y] * p[a.y];
        const CardTexelGpu& t = texels[c.first.x + i + c.info.z * j];
        if (rr < 0.9f * 0.9f * r * r) {
          const float surface = std::abs(c.plane.z) - std::sqrt(r * r - rr);
          EXPECT_GE(t.depth, surface - 1e-4f);
          EXPECT_LE(t.depth, surface + facet / std::sqrt(1.0f - rr / (r * r)) + 1e-4f);
          ++inside;
        } else if (rr > r * r * 1.0001f) {
          EXPECT_LT(t.depth, 0.0f);
          EXPECT_EQ(t.albedo, 0u);
          ++outside;
        }
      }
  }
  EXPECT_GT(inside, 1000u);
  EXPECT_GT(outside, 500u);
}

TEST(CardCaptureCpu, TheNearestOfOverlappingTrianglesWins) {
  // Two parallel squares seen by the +z card: the upper one (z = 0.5) hides the lower one.
  TriangleScene m;
  m.materials.resize(2);
  m.materials[0].baseColorFactor = glm::vec4(1, 0, 0, 1);
  m.materials[1].baseColorFactor = glm::vec4(0, 0, 1, 1);
  for (float z : {0.0f, 0.5f}) {
    const std::uint32_t b = std::uint32_t(m.positions.size());
    m.positions.insert(m.positions.end(), {{0, 0, z}, {1, 0, z}, {1, 1, z}, {0, 1, z}});
    m.triangles.insert(m.triangles.end(), {{b, b + 1, b + 2}, {b, b + 2, b + 3}});
    m.triangleMaterial.insert(m.triangleMaterial.end(), 2, z > 0 ? 1u : 0u);
  }
  m.uvs.assign(m.positions.size(), glm::vec2(0));
  const MeshCards cards = layoutCards(m.boundsMin(), m.boundsMax(), 0.1f);
  const auto texels = resolveCardTexels(m, cards, captureCardsCpu(m, cards));
  const CardGpu& top = cards.cards[4];     // sees the + z side
  const CardGpu& bottom = cards.cards[5];  // sees the − z side
  for (std::uint32_t k = 0; k < top.info.z * top.info.w; ++k) {
    EXPECT_EQ(texels[top.first.x + k].albedo, packAlbedo({0, 0, 1, 1}));
    EXPECT_EQ(texels[bottom.first.x + k].albedo, packAlbedo({1, 0, 0, 1}));
    // An open sheet's normal faces the card that sees it.
    EXPECT_LT(gpu_shared::cardUnpackNormal(texels[bottom.first.x + k].normal).z, -0.9999f);
  }
}

}  // namespace
}  // namespace sdfstream
