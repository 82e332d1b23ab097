// The GPU capture (a graphics pipeline on the device) against captureCardsCpu: the same
// orthographic rasterization at texel centres, with vertices snapped to 1/256 texel and a
// top-left tie rule. Another GPU may snap or break ties differently, so the two may disagree
// where a texel centre lies on (within a few 1/256 texel of) a triangle edge; everywhere else
// they must pick the same triangle, and the resolved texels must agree to the interpolation's
// precision.
#include "cards/card_rasterizer.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>

#include <gtest/gtest.h>

#include "objects/primitive_meshes.h"
#include "tests/support/gpu_test.h"

namespace sdfstream {
namespace {

using gpu_shared::CardGpu;
using gpu_shared::CardTexelGpu;

class CardRasterizer : public test::GpuTest {};

// Distance in texels from texel (i, j)'s centre to the nearest edge of triangle t as card c
// projects it.
float edgeDistanceTexels(const TriangleScene& mesh, const CardGpu& c, std::uint32_t t,
                         std::uint32_t i, std::uint32_t j) {
  const glm::ivec3 a = cardAxes(c);
  glm::vec2 q[3];
  for (int k = 0; k < 3; ++k) {
    const glm::vec3 p = mesh.positions[mesh.triangles[t][k]];
    q[k] = {(p[a.x] - c.plane.x) / c.texel.x, (p[a.y] - c.plane.y) / c.texel.y};
  }
  const glm::vec2 p(float(i) + 0.5f, float(j) + 0.5f);
  float best = 1e30f;
  for (int k = 0; k < 3; ++k) {
    const glm::vec2 e = q[(k + 1) % 3] - q[k];
    const float len = glm::length(e);
    if (len <= 0.0f) continue;
    const float s = std::clamp(glm::dot(p - q[k], e) / (len * len), 0.0f, 1.0f);
    best = std::min(best, glm::length(p - (q[k] + s * e)));
  }
  return best;
}

struct Agreement {
  std::size_t texels = 0, differ = 0, unexplained = 0;
  float worstDepth = 0, worstBary = 0;
  int worstAlbedo = 0;
};

Agreement compare(const TriangleScene& mesh, const MeshCards& cards,
                  const std::vector<CardVisibility>& gpu, const std::vector<CardVisibility>& cpu) {
  Agreement r;
  const glm::vec3 extent = cards.boxMax - cards.boxMin;
  const float size = std::max(extent.x, std::max(extent.y, extent.z));
  for (const CardGpu& c : cards.cards)
    for (std::uint32_t j = 0; j < c.info.w; ++j)
      for (std::uint32_t i = 0; i < c.info.z; ++i) {
        const std::size_t k = c.first.x + i + c.info.z * j;
        ++r.texels;
        const CardTexelGpu g = resolveCardTexel(mesh, c, gpu[k]);
        const CardTexelGpu h = resolveCardTexel(mesh, c, cpu[k]);
        if (gpu[k].triangle != cpu[k].triangle) {
          ++r.differ;
          // Explained: a texel centre on an edge of either triangle (sub-pixel snapping), or two
          // surfaces at the same depth (a shared edge seen edge-on, coplanar overlaps).
          const bool onEdge =
              (cpu[k].triangle && edgeDistanceTexels(mesh, c, cpu[k].triangle - 1, i, j) < 0.02f) ||
              (gpu[k].triangle && edgeDistanceTexels(mesh, c, gpu[k].triangle - 1, i, j) < 0.02f);
          const bool sameDepth =
              g.depth >= 0 && h.depth >= 0 && std::abs(g.depth - h.depth) < 1e-4f * size;
          if (!onEdge && !sameDepth) ++r.unexplained;
          continue;
        }
        if (!gpu[k].triangle) continue;
        r.worstBary = std::max(r.worstBary, glm::length(gpu[k].bary - cpu[k].bary));
        r.worstDepth = std::max(r.worstDepth, std::abs(g.depth - h.depth) / size);
        for (int ch = 0; ch < 4; ++ch)
          r.worstAlbedo = std::max(r.worstAlbedo, std::abs(int((g.albedo >> (8 * ch)) & 255u) -
                                                           int((h.albedo >> (8 * ch)) & 255u)));
        EXPECT_EQ(g.normal, h.normal);
        EXPECT_EQ(g.emission, h.emission);
      }
  std::printf(
      "%zu texels: %zu differ (%.3f%%), %zu unexplained; worst |Δbary| %.2e, |Δdepth| "
      "%.2e of the box, |Δalbedo| %d/255\n",
      r.texels, r.differ, 100.0 * double(r.differ) / double(r.texels), r.unexplained, r.worstBary,
      r.worstDepth, r.worstAlbedo);
  return r;
}

// 300 random triangles of random sizes in [-1, 1]³, overlapping and interpenetrating, half of
// them textured (a 4×4 checker sampled through per-vertex UVs), one of them emissive.
TriangleScene randomSoup() {
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f), size(0.05f, 0.6f), uv(0.0f, 1.0f);
  TriangleScene m;
  m.materials.resize(3);
  m.materials[0].baseColorFactor = glm::vec4(0.2f, 0.7f, 0.3f, 1.0f);
  m.materials[1].baseColorTexture = 0;
  m.materials[2].emissive = glm::vec3(4.0f, 2.0f, 0.5f);
  Texture checker;
  checker.width = checker.height = 4;
  for (int y = 0; y < 4; ++y)
    for (int x = 0; x < 4; ++x) {
      const std::uint8_t v = (x + y) % 2 ? 230 : 20;
      checker.rgba.insert(checker.rgba.end(), {v, std::uint8_t(255 - v), 128, 255});
    }
  m.textures.push_back(checker);
  for (std::uint32_t t = 0; t < 300; ++t) {
    const glm::vec3 centre(u(rng), u(rng), u(rng));
    const float s = size(rng);
    const std::uint32_t b = std::uint32_t(m.positions.size());
    for (int k = 0; k < 3; ++k) {
      m.positions.push_back(
          glm::clamp(centre + s * glm::vec3(u(rng), u(rng), u(rng)), -1.0f, 1.0f));
      m.uvs.push_back({uv(rng), uv(rng)});
    }
    m.triangles.push_back({b, b + 1, b + 2});
    m.triangleMaterial.push_back(t == 0 ? 2u : t % 2);
  }
  return m;
}

void expectAgreement(const Agreement& a) {
  EXPECT_EQ(a.unexplained, 0u);
  // Texel centres on edges are common where the mesh's edges follow the texel grid's diagonals
  // (the sphere's meridians: 3% of its texels with the opposite tie rule). lavapipe agrees on
  // every texel; the bound allows another GPU's tie rule but catches a systematic offset.
  EXPECT_LT(double(a.differ), 0.05 * double(a.texels));
  // Measured on lavapipe: |Δbary| <= 1.6e-4, |Δdepth| <= 1.2e-5 of the box, |Δalbedo| <= 1.
  EXPECT_LT(a.worstBary, 1e-3f);
  EXPECT_LT(a.worstDepth, 1e-4f);
  EXPECT_LE(a.worstAlbedo, 2);
}

TEST_F(CardRasterizer, BoxSphereAndATexturedSoupMatchTheCpuReference) {
  sdfstream::CardRasterizer raster(ctx());
  const TriangleScene meshes[] = {
      makeBoxMesh({0.5f, 0.3f, 0.2f}, glm::vec4(0.8f, 0.1f, 0.1f, 1.0f)),
      makeSphereMesh(0.7f, glm::vec4(0.5f), 32),
      randomSoup(),
  };
  const float voxels[] = {0.02f, 0.03f, 0.02f};
  for (int m = 0; m < 3; ++m) {
    const MeshCards cards = layoutCards(meshes[m].boundsMin(), meshes[m].boundsMax(), voxels[m]);
    const auto gpu = raster.capture(meshes[m], cards);
    const auto cpu = captureCardsCpu(meshes[m], cards);
    ASSERT_EQ(gpu.size(), cpu.size());
    const std::size_t seen =
        std::count_if(cpu.begin(), cpu.end(), [](const CardVisibility& v) { return v.triangle; });
    EXPECT_GT(seen, cpu.size() / 4) << m;  // the comparison covers real surfaces
    expectAgreement(compare(meshes[m], cards, gpu, cpu));
    EXPECT_GE(raster.lastMilliseconds(), 0.0);
  }
}

TEST_F(CardRasterizer, ASmallerMeshAfterALargerOneReusesTheTarget) {
  sdfstream::CardRasterizer raster(ctx());
  const TriangleScene big = makeBoxMesh({1.0f, 1.0f, 1.0f}, glm::vec4(1.0f));
  const TriangleScene small = makeBoxMesh({0.2f, 0.1f, 0.1f}, glm::vec4(0.0f, 1.0f, 0.0f, 1.0f));
  const MeshCards bigCards = layoutCards(big.boundsMin(), big.boundsMax(), 0.05f);
  const MeshCards smallCards = layoutCards(small.boundsMin(), small.boundsMax(), 0.05f);
  raster.capture(big, bigCards);
  // Texels of the small capture outside its cards must not leak in from the big one.
  const auto gpu = raster.capture(small, smallCards);
  expectAgreement(compare(small, smallCards, gpu, captureCardsCpu(small, smallCards)));
}

}  // namespace
}  // namespace sdfstream
