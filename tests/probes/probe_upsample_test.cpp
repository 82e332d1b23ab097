// Reduced-resolution sampling's CPU side (gi/probe_upsample.h, shaders/probe_upsample.glsl), at
// half and quarter resolution: the order the sampling pass visits the blocks in, which pixel of a
// block is sampled, and the upsample on synthetic images whose right answer is known.
#include <cstdio>
#include <functional>
#include <set>
#include <vector>

#include <gtest/gtest.h>

#include "gi/probe_upsample.h"

namespace sdfstream::probe {
namespace {
using gpu_shared::ProbeQuery;

ProbeQuery query(glm::vec3 p, glm::vec3 n) {
  return ProbeQuery{glm::vec4(p, 0.0f), glm::vec4(n, 0.0f), glm::vec4(0.0f, 0.0f, 1.0f, 0.0f)};
}

// What the sampling pass would write, with `irradiance` standing for the probe field: the plan's
// queries "sampled" by a function of the query.
std::vector<glm::vec3> upsampleWith(const std::vector<ProbeQuery>& image, std::uint32_t w,
                                    std::uint32_t h, std::uint32_t block,
                                    const std::function<glm::vec3(const ProbeQuery&)>& irradiance) {
  const HalfResolutionPlan plan = planHalfResolution(image, w, h, block);
  std::vector<glm::vec3> sampled(plan.queries.size());
  for (std::size_t i = 0; i < sampled.size(); ++i)
    sampled[i] =
        plan.sampledPixel[i] < block * block ? irradiance(plan.queries[i]) : glm::vec3(-7.0f);
  return upsampleHalfResolution(image, halfResolutionSamples(plan, sampled), w, h, block);
}

// The block size: 2 (half resolution) or 4 (quarter).
class ReducedResolution : public ::testing::TestWithParam<std::uint32_t> {};
INSTANTIATE_TEST_SUITE_P(BlockSizes, ReducedResolution, ::testing::Values(2u, 4u));

TEST_P(ReducedResolution, TileOrderVisitsEveryBlockOnce) {
  const std::uint32_t s = GetParam();
  for (auto [w, h] : {std::pair{1u, 1u}, {2u, 2u}, {17u, 9u}, {64u, 48u}, {1919u, 1081u}}) {
    const std::vector<ProbeQuery> image(std::size_t(w) * h, query(glm::vec3(1.0f), {0, 1, 0}));
    const HalfResolutionPlan plan = planHalfResolution(image, w, h, s);
    EXPECT_EQ(plan.lowWidth, (w + s - 1) / s);
    EXPECT_EQ(plan.lowHeight, (h + s - 1) / s);
    EXPECT_EQ(plan.queries.size() % 64, 0u);
    std::set<std::uint32_t> seen;
    for (std::uint32_t low : plan.lowPixel)
      if (low != ~0u) EXPECT_TRUE(seen.insert(low).second) << "block " << low << " twice";
    EXPECT_EQ(seen.size(), std::size_t(plan.lowWidth) * plan.lowHeight) << w << "x" << h;
    // Every block has a surface here: the first pixel of each is sampled.
    for (std::size_t i = 0; i < plan.lowPixel.size(); ++i)
      if (plan.lowPixel[i] != ~0u) EXPECT_EQ(plan.sampledPixel[i], 0u);
  }
  // Eight consecutive invocations are a 4×2 block of neighbouring blocks (the sampling pass's
  // SDF-test sharing groups).
  const std::vector<ProbeQuery> image(128 * 128, query(glm::vec3(1.0f), {0, 1, 0}));
  const HalfResolutionPlan plan = planHalfResolution(image, 128, 128, s);
  for (std::size_t g = 0; g < plan.lowPixel.size(); g += 8) {
    std::uint32_t minX = 99, maxX = 0, minY = 99, maxY = 0;
    for (std::size_t k = g; k < g + 8; ++k) {
      const std::uint32_t x = plan.lowPixel[k] % plan.lowWidth,
                          y = plan.lowPixel[k] / plan.lowWidth;
      minX = std::min(minX, x), maxX = std::max(maxX, x);
      minY = std::min(minY, y), maxY = std::max(maxY, y);
    }
    EXPECT_EQ(maxX - minX, 3u);
    EXPECT_EQ(maxY - minY, 1u);
  }
}

TEST(HalfResolution, BlocksSampleTheirFirstPixelWithASurface) {
  // A 4×2 image: block 0's first two pixels have no surface, block 1 has none at all.
  std::vector<ProbeQuery> image(8, query(glm::vec3(0.0f), glm::vec3(0.0f)));
  image[4] = query({0, 1, 0}, {0, 0, 1});  // block 0, pixel (0, 1)
  image[5] = query({1, 1, 0}, {0, 0, 1});  // block 0, pixel (1, 1)
  const HalfResolutionPlan plan = planHalfResolution(image, 4, 2);
  ASSERT_EQ(plan.lowWidth, 2u);
  for (std::size_t i = 0; i < plan.lowPixel.size(); ++i) {
    if (plan.lowPixel[i] == 0) {
      EXPECT_EQ(plan.sampledPixel[i], 2u);
      EXPECT_EQ(plan.queries[i].position, image[4].position);
    } else if (plan.lowPixel[i] == 1) {
      EXPECT_EQ(plan.sampledPixel[i], 4u);
      EXPECT_EQ(glm::vec3(plan.queries[i].normal), glm::vec3(0.0f));
    }
  }
  const std::vector<glm::vec3> e =
      upsampleWith(image, 4, 2, 2, [](const ProbeQuery& q) { return glm::vec3(q.position.x + 2); });
  EXPECT_EQ(e[4], glm::vec3(2.0f));  // sampled: its own value
  EXPECT_EQ(e[5], glm::vec3(2.0f));  // its block's only sample
  for (int i : {0, 1, 2, 3, 6, 7}) EXPECT_EQ(e[i], glm::vec3(0.0f)) << i;  // no surface
}

TEST(QuarterResolution, BlocksSampleTheirFirstPixelWithASurfaceRowByRow) {
  // An 8×4 image: block 0's surface starts at its pixel (2, 1) (index 6), block 1 has none.
  std::vector<ProbeQuery> image(32, query(glm::vec3(0.0f), glm::vec3(0.0f)));
  for (int i : {10, 11, 17, 26}) image[i] = query({float(i % 8), float(i / 8), 0}, {0, 0, 1});
  const HalfResolutionPlan plan = planHalfResolution(image, 8, 4, 4);
  ASSERT_EQ(plan.lowWidth, 2u);
  ASSERT_EQ(plan.lowHeight, 1u);
  int seen = 0;
  for (std::size_t i = 0; i < plan.lowPixel.size(); ++i) {
    if (plan.lowPixel[i] == 0) {
      EXPECT_EQ(plan.sampledPixel[i], 6u);  // (2, 1): image pixel 10
      EXPECT_EQ(plan.queries[i].position, image[10].position);
      ++seen;
    } else if (plan.lowPixel[i] == 1) {
      EXPECT_EQ(plan.sampledPixel[i], 16u);
      EXPECT_EQ(glm::vec3(plan.queries[i].normal), glm::vec3(0.0f));
      ++seen;
    }
  }
  EXPECT_EQ(seen, 2);
  const std::vector<glm::vec3> e =
      upsampleWith(image, 8, 4, 4, [](const ProbeQuery& q) { return glm::vec3(q.position.x + 2); });
  EXPECT_EQ(e[10], glm::vec3(4.0f));                                 // sampled: its own value
  for (int i : {11, 17, 26}) EXPECT_EQ(e[i], glm::vec3(4.0f)) << i;  // the block's only sample
  EXPECT_EQ(e[0], glm::vec3(0.0f));                                  // no surface
}

// One plane seen head-on with irradiance linear in position: bilinear upsampling reproduces a
// linear function, so away from the image's edge (where the footprint is clamped) every pixel
// gets its own value.
TEST_P(ReducedResolution, LinearIrradianceOnAPlaneIsReproduced) {
  const std::uint32_t s = GetParam();
  const std::uint32_t w = 40, h = 30;
  std::vector<ProbeQuery> image;
  for (std::uint32_t y = 0; y < h; ++y)
    for (std::uint32_t x = 0; x < w; ++x)
      image.push_back(query(glm::vec3(0.3f * x, 0.3f * y, 5.0f), {0, 0, 1}));
  auto linear = [](const ProbeQuery& q) {
    return glm::vec3(1.0f + 0.05f * q.position.x, 2.0f - 0.03f * q.position.y, 0.5f);
  };
  const std::vector<glm::vec3> e = upsampleWith(image, w, h, s, linear);
  float worst = 0.0f;
  // The last block of each row and column has no next sample to interpolate towards.
  for (std::uint32_t y = 0; y + s < h; ++y)
    for (std::uint32_t x = 0; x + s < w; ++x) {
      const glm::vec3 want = linear(image[x + w * y]);
      worst = std::max(worst, glm::length(e[x + w * y] - want) / glm::length(want));
    }
  std::printf("[figures] linear irradiance on a plane, %ux%u blocks: worst rel error %.2e\n", s, s,
              worst);
  EXPECT_LT(worst, 1e-5f);
}

// A pole in front of a wall, and a floor meeting the wall: every pixel takes its irradiance from
// samples on its own surface only (the wall 40 voxels behind the pole, the floor at right
// angles to the wall), though most of its bilinear neighbours lie on another. The pole is 3
// pixels wide at half resolution and 8 at quarter: a feature with no block whose first surface
// pixel lies on it has no sample of its own, and takes its most similar neighbour's.
TEST_P(ReducedResolution, SurfacesDoNotBleedIntoEachOther) {
  const std::uint32_t s = GetParam();
  const std::uint32_t w = 48, h = 32, poleEnd = s == 2 ? 23 : 28;
  std::vector<ProbeQuery> image;
  std::vector<int> surface;
  for (std::uint32_t y = 0; y < h; ++y)
    for (std::uint32_t x = 0; x < w; ++x) {
      if (y < 8) {  // floor (normal +y), receding
        image.push_back(query(glm::vec3(0.5f * x, 0.0f, 20.0f - 0.5f * y), {0, 1, 0}));
        surface.push_back(0);
      } else if (x >= 21 && x <= poleEnd) {  // a pole, 40 voxels in front of the wall
        image.push_back(query(glm::vec3(0.5f * x, 0.5f * y, 50.0f), {0, 0, 1}));
        surface.push_back(1);
      } else {  // wall (normal +z)
        image.push_back(query(glm::vec3(0.5f * x, 0.5f * y, 10.0f), {0, 0, 1}));
        surface.push_back(2);
      }
    }
  const glm::vec3 colours[3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  auto bySurface = [&](const ProbeQuery& q) {
    return q.normal.y > 0.5f ? colours[0] : q.position.z > 30.0f ? colours[1] : colours[2];
  };
  const std::vector<glm::vec3> e = upsampleWith(image, w, h, s, bySurface);
  float worst = 0.0f;
  for (std::size_t i = 0; i < e.size(); ++i)
    worst = std::max(worst, glm::length(e[i] - colours[surface[i]]));
  std::printf("[figures] pole, wall and floor in %ux%u blocks: worst bleed %.2e\n", s, s, worst);
  // Quarter resolution's samples lie twice as far apart, so a pixel's own surface's neighbours
  // have less bilinear weight against the wall's residual similarity (~3e-4 at 40 voxels).
  EXPECT_LT(worst, s == 2 ? 1e-3f : 2e-3f);
}

TEST(HalfResolution, SimilarityFallsWithNormalAndPlaneDistance) {
  const glm::vec3 p(0.0f), n(0.0f, 1.0f, 0.0f);
  EXPECT_FLOAT_EQ(upsampleSimilarity(p, n, {3, 0, 0}, n), 1.0f);    // coplanar
  EXPECT_FLOAT_EQ(upsampleSimilarity(p, n, {30, 0, 0}, n), 1.0f);   // far, coplanar
  EXPECT_EQ(upsampleSimilarity(p, n, {1, 0, 0}, {1, 0, 0}), 0.0f);  // at right angles
  EXPECT_LT(upsampleSimilarity(p, n, {1, 4, 0}, n), 0.02f);         // a 4-voxel step
  EXPECT_GT(upsampleSimilarity(p, n, {1, 0.2f, 0}, n), 0.9f);       // a slight bump
  EXPECT_NEAR(upsampleSimilarity(p, n, {1, 0, 0}, glm::normalize(glm::vec3(0, 1, 0.4348f))), 0.5f,
              0.01f);  // 23.5 degrees apart
}

}  // namespace
}  // namespace sdfstream::probe
