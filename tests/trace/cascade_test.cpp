// Cascade image invariants: page-table entries point at the right bricks, and every empty page's
// distance bound is conservative against a brute-force search over resident bricks.
#include <gtest/gtest.h>

#include <algorithm>
#include <map>
#include <random>
#include <set>
#include <tuple>

#include "streaming/cascade.h"

namespace sdfstream {
namespace {

World randomWorld(unsigned seed, int bricks) {
  std::mt19937 rng(seed);
  std::uniform_int_distribution<int> coord(-4, 20);
  World w;
  w.voxelSize = 0.25;
  std::set<std::tuple<int, int, int>> used;
  while (int(w.bricks.size()) < bricks) {
    glm::ivec3 c(coord(rng), coord(rng), coord(rng));
    if (!used.insert({c.x, c.y, c.z}).second) continue;
    Brick b;
    b.coord = c;
    b.distance.fill(std::uint16_t(c.x & 0xffff));  // a tag to recognise the brick in the atlas
    b.albedo.fill(std::uint32_t(c.x * 1000 + c.y * 100 + c.z + 100000));
    w.bricks.push_back(b);
  }
  std::sort(w.bricks.begin(), w.bricks.end(),
            [](const Brick& a, const Brick& b) { return brickCoordLess(a.coord, b.coord); });
  return w;
}

TEST(Cascade, PagesMapToTheirBricksAndBoundsAreConservative) {
  World w = randomWorld(7, 60);
  const glm::ivec3 origin(-3, 1, 2);  // not a multiple of 16: exercises toroidal addressing
  CascadeImage c = buildCascade(w, origin);
  std::map<std::tuple<int, int, int>, const Brick*> byCoord;
  for (const auto& b : w.bricks) byCoord[{b.coord.x, b.coord.y, b.coord.z}] = &b;

  std::vector<glm::ivec3> residentPages;
  for (int z = 0; z < 16; ++z)
    for (int y = 0; y < 16; ++y)
      for (int x = 0; x < 16; ++x) {
        glm::ivec3 world = origin + glm::ivec3(x, y, z);
        std::uint32_t e = c.pageTable[c.pageIndex({x, y, z})];
        auto it = byCoord.find({world.x, world.y, world.z});
        ASSERT_EQ(bool(e & layout::kPageResidentBit), it != byCoord.end());
        if (it != byCoord.end()) {
          std::uint32_t slot = e & layout::kPagePayloadMask;
          EXPECT_EQ(c.albedoAtlas[slot * layout::kBrickMaterialCount], it->second->albedo[0]);
          residentPages.push_back({x, y, z});
        }
      }
  EXPECT_EQ(c.residentBricks, residentPages.size());
  ASSERT_FALSE(residentPages.empty());

  int tight = 0;
  for (int z = 0; z < 16; ++z)
    for (int y = 0; y < 16; ++y)
      for (int x = 0; x < 16; ++x) {
        std::uint32_t e = c.pageTable[c.pageIndex({x, y, z})];
        if (e & layout::kPageResidentBit) continue;
        // Exact minimum distance (voxels) between this page's box and any resident page's box.
        double best = 1e30;
        for (glm::ivec3 r : residentPages) {
          glm::dvec3 gap(std::max(0, std::abs(r.x - x) - 1), std::max(0, std::abs(r.y - y) - 1),
                         std::max(0, std::abs(r.z - z) - 1));
          best = std::min(best, glm::length(gap * 8.0));
        }
        double bound = double(e & layout::kPagePayloadMask);
        EXPECT_LE(bound, best) << "page " << x << "," << y << "," << z;
        if (bound > 0 && bound == best) ++tight;
      }
  EXPECT_GT(tight, 0);  // the bound is not trivially zero everywhere
}

TEST(Cascade, ToCascadeAndBackRoundTrip) {
  World w = randomWorld(3, 4);
  w.origin = glm::dvec3(1000.5, -20.25, 3.0);
  CascadeImage c = buildCascade(w, glm::ivec3(5, -2, 7));
  glm::dvec3 p(1010.0, -15.0, 20.0);
  glm::dvec3 back = c.toWorld(c.toCascade(p));
  EXPECT_NEAR(back.x, p.x, 1e-4);
  EXPECT_NEAR(back.y, p.y, 1e-4);
  EXPECT_NEAR(back.z, p.z, 1e-4);
}

}  // namespace
}  // namespace sdfstream
