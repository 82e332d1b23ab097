// Octahedral mapping and border copy of the probe tiles (shaders/probe_math.glsl via
// gi/probe_math.h): round trips, texel centres, the seam symmetry the border rule relies on, a
// hand-worked 8x8 border, and bilinear continuity across the seams.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "gi/probe_math.h"

namespace sdfstream::probe {
namespace {

std::vector<glm::vec3> randomDirections(std::size_t n, std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<float> g(0.0f, 1.0f);
  std::vector<glm::vec3> dirs;
  while (dirs.size() < n) {
    glm::vec3 v(g(rng), g(rng), g(rng));
    if (glm::length(v) > 1e-3f) dirs.push_back(glm::normalize(v));
  }
  return dirs;
}

float angleBetween(glm::vec3 a, glm::vec3 b) {
  // atan2(|a x b|, a.b) stays accurate for tiny angles, unlike acos.
  return std::atan2(glm::length(glm::cross(a, b)), glm::dot(a, b));
}

TEST(Octahedral, RoundTripOfUnitDirections) {
  std::vector<glm::vec3> dirs = randomDirections(200000, 7u);
  // The places where the fold changes: poles, equator, octant boundaries.
  for (glm::vec3 d : {glm::vec3(0, 0, 1), glm::vec3(0, 0, -1), glm::vec3(1, 0, 0),
                      glm::vec3(-1, 0, 0), glm::vec3(0, 1, 0), glm::vec3(0, -1, 0),
                      glm::vec3(0.6f, -0.8f, 0.0f), glm::vec3(-0.6f, 0.0f, -0.8f)}) {
    dirs.push_back(glm::normalize(d));
  }
  float maxAngle = 0.0f;
  for (glm::vec3 d : dirs) {
    const glm::vec2 p = octEncode(d);
    ASSERT_LE(std::abs(p.x), 1.0f);
    ASSERT_LE(std::abs(p.y), 1.0f);
    const glm::vec3 back = octDecode(p);
    ASSERT_NEAR(glm::length(back), 1.0f, 1e-6f);
    maxAngle = std::max(maxAngle, angleBetween(d, back));
  }
  std::printf("[ measure  ] octahedral round trip, %zu dirs: max angular error %.3g rad\n",
              dirs.size(), maxAngle);
  EXPECT_LT(maxAngle, 2e-6f);  // a few float ulps; a wrong fold would give ~1 rad
}

TEST(Octahedral, EveryTexelCentreDecodesInsideItsTexel) {
  for (std::uint32_t interior :
       {gpu_shared::kProbeIrradianceInterior, gpu_shared::kProbeDepthInterior}) {
    for (std::uint32_t y = 0; y < interior; ++y) {
      for (std::uint32_t x = 0; x < interior; ++x) {
        const glm::vec3 d = texelDirection(glm::uvec2(x, y), interior);
        const glm::vec2 c = tileCoord(d, interior);
        // Tile texel (x+1, y+1) covers [x+1, x+2) x [y+1, y+2); its centre is +0.5.
        EXPECT_EQ(static_cast<std::uint32_t>(std::floor(c.x)), x + 1) << interior << " " << x;
        EXPECT_EQ(static_cast<std::uint32_t>(std::floor(c.y)), y + 1) << interior << " " << y;
        EXPECT_NEAR(c.x, x + 1.5f, 1e-4f);
        EXPECT_NEAR(c.y, y + 1.5f, 1e-4f);
      }
    }
  }
}

// The border rule rests on this: on the square's edges, (u, +-1) and (-u, +-1) are the same
// direction, and likewise (+-1, v) and (+-1, -v); all four corners are (0, 0, -1).
TEST(Octahedral, SquareEdgesFoldOntoThemselvesMirrored) {
  for (int i = 0; i <= 40; ++i) {
    const float u = -1.0f + 2.0f * static_cast<float>(i) / 40.0f;
    for (float s : {-1.0f, 1.0f}) {
      EXPECT_LT(angleBetween(octDecode({u, s}), octDecode({-u, s})), 1e-6f) << u;
      EXPECT_LT(angleBetween(octDecode({s, u}), octDecode({s, -u})), 1e-6f) << u;
    }
  }
  for (glm::vec2 corner :
       {glm::vec2(-1, -1), glm::vec2(1, -1), glm::vec2(-1, 1), glm::vec2(1, 1)}) {
    EXPECT_LT(angleBetween(octDecode(corner), glm::vec3(0, 0, -1)), 1e-6f);
  }
}

// Hand-worked 8x8 tile (6x6 interior + border), as in Majercik 2021 Fig. 12a: interior texels
// are labelled a..z, 0..9 row by row; each border texel must show the label of its source.
// Top row = row 1 mirrored left-right, left column = column 1 mirrored top-bottom, corners =
// diagonally opposite interior corner.
TEST(ProbeBorders, HandWorkedEightByEight) {
  const char* kExpected[8] = {
      "9fedcba4",  //
      "4abcdef9",  //
      "yghijkl3",  //
      "smnopqrx",  //
      "mstuvwxr",  //
      "gyz0123l",  //
      "a456789f",  //
      "f987654a",  //
  };
  const std::string labels = "abcdefghijklmnopqrstuvwxyz0123456789";
  // Through borderSource directly...
  for (std::uint32_t y = 0; y < 8; ++y) {
    std::string row;
    for (std::uint32_t x = 0; x < 8; ++x) {
      const glm::uvec2 s = borderSource({x, y}, 8);
      ASSERT_TRUE(s.x >= 1 && s.x <= 6 && s.y >= 1 && s.y <= 6) << x << "," << y;
      row += labels[(s.y - 1) * 6 + (s.x - 1)];
    }
    EXPECT_EQ(row, kExpected[y]) << "tile row " << y;
  }
  // ...and ProbeTexels::fillBorders on the irradiance tile (its own size; interior labels as
  // values): every texel holds the label of the texel the rule above names.
  ProbeTexels texels;
  auto tile = texels.irradianceTile();
  constexpr std::uint32_t kInterior = gpu_shared::kProbeIrradianceInterior;
  constexpr std::uint32_t kTile = gpu_shared::kProbeIrradianceTexels;
  for (std::uint32_t y = 0; y < kInterior; ++y)
    for (std::uint32_t x = 0; x < kInterior; ++x)
      tile[(y + 1) * kTile + (x + 1)] = glm::vec3(static_cast<float>(y * kInterior + x));
  texels.fillBorders();
  for (std::uint32_t y = 0; y < kTile; ++y) {
    for (std::uint32_t x = 0; x < kTile; ++x) {
      const glm::uvec2 s = borderSource({x, y}, kTile);
      const float want = static_cast<float>((s.y - 1) * kInterior + (s.x - 1));
      EXPECT_EQ(tile[y * kTile + x].x, want) << x << "," << y;
    }
  }
}

// The blend writes each interior texel's border copies itself: the candidates that copy it must
// be exactly the border texels whose source it is, so that every border texel is written once.
TEST(ProbeBorders, EveryBorderTexelIsWrittenOnceByItsSource) {
  for (std::uint32_t tile :
       {8u, gpu_shared::kProbeIrradianceTexels, gpu_shared::kProbeDepthTexels}) {
    std::vector<int> writes(tile * tile, 0);
    for (std::uint32_t y = 1; y + 1 < tile; ++y)
      for (std::uint32_t x = 1; x + 1 < tile; ++x) {
        std::vector<glm::uvec2> copies;
        for (std::uint32_t k = 0; k < 8; ++k) {
          const glm::uvec2 c = borderCopyCandidate({x, y}, tile, k);
          ASSERT_TRUE(c.x < tile && c.y < tile);
          if (borderSource(c, tile) != glm::uvec2(x, y)) continue;
          ASSERT_TRUE(c.x == 0 || c.y == 0 || c.x == tile - 1 || c.y == tile - 1);
          if (std::find(copies.begin(), copies.end(), c) == copies.end()) copies.push_back(c);
        }
        for (const glm::uvec2& c : copies) ++writes[c.y * tile + c.x];
        const bool edgeX = x == 1 || x == tile - 2, edgeY = y == 1 || y == tile - 2;
        EXPECT_EQ(copies.size(), std::size_t(edgeX && edgeY   ? 3
                                             : edgeX || edgeY ? 1
                                                              : 0))
            << "tile " << tile << " texel " << x << "," << y;
      }
    for (std::uint32_t y = 0; y < tile; ++y)
      for (std::uint32_t x = 0; x < tile; ++x) {
        const bool border = x == 0 || y == 0 || x == tile - 1 || y == tile - 1;
        EXPECT_EQ(writes[y * tile + x], border ? 1 : 0) << "tile " << tile << " " << x << "," << y;
      }
  }
}

// With the borders right, bilinear lookups are as accurate across the seams as inside; a wrong
// border (here: left at zero, or clamped to the nearest interior texel) shows at the seams.
TEST(ProbeBorders, BilinearLookupIsContinuousAcrossSeams) {
  auto f = [](glm::vec3 d) { return 2.0f + 0.8f * d.x - 0.5f * d.y + 0.6f * d.z; };
  ProbeTexels texels;
  auto tile = texels.depthTile();  // 16x16: finer, so the interpolation error is small
  for (std::uint32_t y = 0; y < 14; ++y)
    for (std::uint32_t x = 0; x < 14; ++x)
      tile[(y + 1) * 16 + (x + 1)] = glm::vec2(f(texelDirection({x, y}, 14)), 0.0f);
  texels.fillBorders();

  float maxInner = 0.0f, maxSeam = 0.0f;
  for (glm::vec3 d : randomDirections(50000, 11u)) {
    const glm::vec2 c = tileCoord(d, 14);
    const bool nearSeam = c.x < 1.5f || c.y < 1.5f || c.x > 14.5f || c.y > 14.5f;
    const float err = std::abs(texels.sampleDepth(d).x - f(d));
    (nearSeam ? maxSeam : maxInner) = std::max(nearSeam ? maxSeam : maxInner, err);
  }
  std::printf("[ measure  ] bilinear |error| of a linear function: inner %.4f, seam band %.4f\n",
              maxInner, maxSeam);
  EXPECT_LT(maxSeam, 1.5f * maxInner + 1e-3f);

  // Controls: the same lookups with borders that clamp to the adjacent interior texel (no
  // mirroring), and with zeroed borders, both break the bound at the seams.
  auto seamError = [&] {
    float worst = 0.0f;
    for (glm::vec3 d : randomDirections(50000, 11u)) {
      worst = std::max(worst, std::abs(texels.sampleDepth(d).x - f(d)));
    }
    return worst;
  };
  for (std::uint32_t y = 0; y < 16; ++y)
    for (std::uint32_t x = 0; x < 16; ++x)
      tile[y * 16 + x] = tile[glm::clamp(y, 1u, 14u) * 16 + glm::clamp(x, 1u, 14u)];
  const float maxSeamClamped = seamError();
  for (std::uint32_t y = 0; y < 16; ++y)
    for (std::uint32_t x = 0; x < 16; ++x)
      if (x == 0 || y == 0 || x == 15 || y == 15) tile[y * 16 + x] = glm::vec2(0.0f);
  const float maxSeamZero = seamError();
  std::printf("[ measure  ] seam band error with clamped borders %.4f, zero borders %.4f\n",
              maxSeamClamped, maxSeamZero);
  EXPECT_GT(maxSeamClamped, 1.5f * maxInner);
  EXPECT_GT(maxSeamZero, 10.0f * maxSeam);
}

}  // namespace
}  // namespace sdfstream::probe
