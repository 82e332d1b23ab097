// Texture sampling on a hand-made scene: sRGB decode before filtering, bilinear, REPEAT wrap;
// the mip pyramid's box filter and the footprint-filtered tap.
#include <cmath>

#include <gtest/gtest.h>

#include "world/triangle_scene.h"

namespace sdfstream {
namespace {

float srgb(int c) {
  const double v = c / 255.0;
  return float(v <= 0.04045 ? v / 12.92 : std::pow((v + 0.055) / 1.055, 2.4));
}

// One triangle whose UVs equal its xy positions, textured with a 2×1 image: black | white.
TriangleScene twoTexelScene(glm::vec4 factor) {
  TriangleScene s;
  s.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  s.uvs = {{0, 0}, {1, 0}, {0, 1}};
  s.triangles = {{0, 1, 2}};
  s.triangleMaterial = {0};
  Texture t;
  t.width = 2;
  t.height = 1;
  t.rgba = {0, 0, 0, 255, 255, 255, 255, 255};
  s.textures = {t};
  Material m;
  m.baseColorFactor = factor;
  m.baseColorTexture = 0;
  m.emissive = glm::vec3(2.0f);
  m.emissiveTexture = 0;
  s.materials = {m};
  return s;
}

// bary (b1, b2) = uv here, since uv0 = 0, uv1 = (1,0), uv2 = (0,1).
TEST(TriangleSceneSampling, TexelCentresAndBilinearMidpoint) {
  const TriangleScene s = twoTexelScene(glm::vec4(1.0f));
  EXPECT_NEAR(sampleAlbedo(s, 0, {0.25f, 0.5f}).r, 0.0f, 1e-6f);  // black centre
  EXPECT_NEAR(sampleAlbedo(s, 0, {0.75f, 0.5f}).r, 1.0f, 1e-6f);  // white centre
  // Halfway: mean of the decoded (linear) values, not the decode of the mean code (≈0.21).
  EXPECT_NEAR(sampleAlbedo(s, 0, {0.5f, 0.5f}).g, 0.5f, 1e-5f);
  // At u = 0 the left texel blends with its REPEAT neighbour, the right texel.
  EXPECT_NEAR(sampleAlbedo(s, 0, {0.0f, 0.5f}).b, 0.5f, 1e-5f);
  EXPECT_NEAR(sampleAlbedo(s, 0, {0.25f, 0.5f}).a, 1.0f, 1e-6f);
}

TEST(TriangleSceneSampling, FactorMultipliesAndSrgbDecodes) {
  TriangleScene s = twoTexelScene(glm::vec4(0.5f, 1.0f, 0.25f, 1.0f));
  s.textures[0].rgba = {128, 128, 128, 255, 128, 128, 128, 255};
  const glm::vec4 c = sampleAlbedo(s, 0, {0.3f, 0.3f});
  EXPECT_NEAR(c.r, 0.5f * srgb(128), 1e-5f);
  EXPECT_NEAR(c.g, srgb(128), 1e-5f);
  EXPECT_NEAR(c.b, 0.25f * srgb(128), 1e-5f);
  EXPECT_NEAR(sampleEmission(s, 0, {0.3f, 0.3f}).r, 2.0f * srgb(128), 1e-5f);
}

TEST(TriangleSceneSampling, BoundsAndArea) {
  const TriangleScene s = twoTexelScene(glm::vec4(1.0f));
  EXPECT_EQ(s.boundsMin(), glm::vec3(0.0f));
  EXPECT_EQ(s.boundsMax(), glm::vec3(1.0f, 1.0f, 0.0f));
  EXPECT_DOUBLE_EQ(s.surfaceArea(), 0.5);
  EXPECT_EQ(TriangleScene{}.boundsMin(), glm::vec3(0.0f));
}

// A 64 x 64 one-texel checker of black and white on a 1 m triangle whose UVs span the texture:
// 64 texels a metre.
TriangleScene checkerScene() {
  TriangleScene s = twoTexelScene(glm::vec4(1.0f));
  Texture& t = s.textures[0];
  t.width = t.height = 64;
  t.rgba.assign(64 * 64 * 4, 255);
  for (int y = 0; y < 64; ++y)
    for (int x = 0; x < 64; ++x)
      if ((x + y) % 2)
        for (int c = 0; c < 3; ++c) t.rgba[(y * 64 + x) * 4 + c] = 0;
  return s;
}

TEST(TriangleSceneSampling, PyramidBoxFiltersInLinearLight) {
  const TriangleScene s = checkerScene();
  const TexturePyramid p = buildTexturePyramid(s);
  ASSERT_EQ(p.levels.size(), 1u);
  ASSERT_EQ(p.levels[0].size(), 6u);  // 32, 16, 8, 4, 2, 1
  EXPECT_EQ(p.levels[0].back().width, 1);
  // Every texel of level 1 averages two black and two white: linear 0.5, sRGB code 188.
  for (const Texture& level : p.levels[0])
    for (std::size_t i = 0; i < level.rgba.size(); i += 4) {
      ASSERT_EQ(level.rgba[i], 188);
      ASSERT_EQ(level.rgba[i + 3], 255);
    }
}

TEST(TriangleSceneSampling, FootprintPicksTheMipLevel) {
  const TriangleScene s = checkerScene();
  const TexturePyramid p = buildTexturePyramid(s);
  const glm::vec2 centre((10 + 0.5f) / 64.0f, (20 + 0.5f) / 64.0f);  // a white texel's centre
  // No footprint, or one under a texel: the texel itself.
  EXPECT_NEAR(sampleAlbedo(s, p, 0, centre, 0.0f).r, 1.0f, 1e-6f);
  EXPECT_NEAR(sampleAlbedo(s, p, 0, centre, 0.5f / 64.0f).r, 1.0f, 1e-6f);
  // Four texels a pixel (level 2) and more: the checker's mean, linear 0.5 (sRGB 188 decoded).
  EXPECT_NEAR(sampleAlbedo(s, p, 0, centre, 4.0f / 64.0f).r, srgb(188), 1e-5f);
  EXPECT_NEAR(sampleAlbedo(s, p, 0, centre, 100.0f).g, srgb(188), 1e-5f);
  // Halfway between levels 0 and 1 (sqrt 2 texels): halfway between white and the mean.
  EXPECT_NEAR(sampleAlbedo(s, p, 0, centre, std::sqrt(2.0f) / 64.0f).b, 0.5f * (1.0f + srgb(188)),
              1e-4f);
}

}  // namespace
}  // namespace sdfstream
