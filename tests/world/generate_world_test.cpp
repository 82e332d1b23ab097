// world/generate_world.h and world/world_plan.h on the real terrain (trigger-rally-data) and
// Sweet Home 3D's models (sweethome3d-furniture), both installed by scripts/setup: the same seed
// gives the same world, trees stand clear of houses and roads, every street lamp and the hall's
// strips glow, the hall has walls on its long sides and open doors on its ends, and the flight's
// waypoints are in the open air. (The flight between waypoints: tests/demo/showcase_flight_test.)
#include <fstream>
#include <sstream>
#include <string>

#include <gtest/gtest.h>

#include "core/error.h"
#include "tests/support/generated_world.h"
#include "tests/support/test_data.h"
#include "world/box_architecture.h"
#include "world/generate_world.h"
#include "world/scene_layout.h"
#include "world/world_plan.h"

namespace sdfstream {
namespace {

namespace fs = std::filesystem;

std::string slurp(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

TEST(GenerateWorld, SameSeedSameWorldAndTheLayoutLoads) {
  SDFSTREAM_REQUIRE_WORLD_PACKAGES();
  GenerateWorldOptions o;
  o.dir = test::scratchDir("generate-world-a");
  const GeneratedWorld a = generateWorld(o);
  o.dir = test::scratchDir("generate-world-b");
  const GeneratedWorld b = generateWorld(o);
  EXPECT_EQ(slurp(a.flight), slurp(b.flight));
  EXPECT_EQ(a.placements, b.placements);
  EXPECT_GE(a.villages, 4);
  EXPECT_GE(a.houses, 60);
  EXPECT_GE(a.lamps, 20);
  const ParsedLayout la = parseLayout(a.layout), lb = parseLayout(b.layout);
  EXPECT_EQ(la.boxes.positions, lb.boxes.positions);
  ASSERT_EQ(la.assets.size(), lb.assets.size());
  for (std::size_t i = 0; i < la.assets.size(); ++i) {
    ASSERT_EQ(la.assets[i].placements.size(), lb.assets[i].placements.size());
    for (std::size_t k = 0; k < la.assets[i].placements.size(); ++k)
      EXPECT_EQ(la.assets[i].placements[k].translation, lb.assets[i].placements[k].translation);
  }
  // Every model the plan uses loads, stand-ins included.
  for (const LayoutAsset& asset : la.assets)
    EXPECT_NO_THROW(loadLayoutAsset(la, asset)) << asset.key;
  // Without settlements: the scattered assets only, no flight.
  o.dir = test::scratchDir("generate-world-plain");
  o.settlements = false;
  const GeneratedWorld plain = generateWorld(o);
  EXPECT_TRUE(plain.flight.empty());
  EXPECT_FALSE(parseLayout(plain.layout).boxes.triangles.size());
}

TEST(GenerateWorld, SettlementsNeedRoom) {
  SDFSTREAM_REQUIRE_WORLD_PACKAGES();
  GenerateWorldOptions o;
  o.dir = test::scratchDir("generate-world-small");
  o.sizeKm = 1.0;
  EXPECT_THROW(generateWorld(o), InputError);
  o.settlements = false;
  EXPECT_NO_THROW(generateWorld(o));
}

class WorldPlanTest : public ::testing::Test {
 protected:
  void SetUp() override {
    SDFSTREAM_REQUIRE_WORLD_PACKAGES();
    test::GeneratedPlan g = test::generatedPlan("world-plan");
    field_ = std::move(g.terrain);
    plan_ = std::move(g.plan);
  }
  std::unique_ptr<Heightfield> field_;
  WorldPlan plan_;
};

TEST_F(WorldPlanTest, TreesStandClearOfEveryBuildingAndRoad) {
  int trees = 0;
  for (const PlannedAsset& a : plan_.assets) {
    if (a.kind != PlanAsset::Conifer && a.kind != PlanAsset::Broadleaf && a.kind != PlanAsset::Bush)
      continue;
    ++trees;
    for (const LayoutBox& b : plan_.boxes)
      ASSERT_FALSE(a.at.x > b.min.x - 0.5 && a.at.x < b.max.x + 0.5 && a.at.y > b.min.z - 0.5 &&
                   a.at.y < b.max.z + 0.5)
          << "a tree at " << a.at.x << "," << a.at.y << " stands in the box " << b.min.x << ","
          << b.min.z << " .. " << b.max.x << "," << b.max.z;
  }
  EXPECT_GT(trees, 500);
}

TEST_F(WorldPlanTest, LampsAndHallStripsGlowAndTheHallIsOpenOnlyAtItsDoors) {
  int glowing = 0;
  for (const LayoutBox& b : plan_.boxes) glowing += b.emission != glm::vec3(0.0f);
  EXPECT_EQ(glowing, plan_.lamps + 3);

  // From the hall's centre at door height: walls across z (the long sides), open along x (the
  // doors), a roof above and a floor below.
  const glm::dvec2 c = (plan_.hallLo + plan_.hallHi) / 2.0;
  const double y = plan_.hallFloor + 5.0;
  auto blocked = [&](glm::dvec3 dir, double distance) {
    for (double s = 0.0; s <= distance; s += 0.25)
      for (const LayoutBox& b : plan_.boxes)
        if (test::insideBox(b, glm::dvec3(c.x, y, c.y) + dir * s, 0.0)) return true;
    return false;
  };
  const double halfX = (plan_.hallHi.x - plan_.hallLo.x) / 2.0;
  const double halfZ = (plan_.hallHi.y - plan_.hallLo.y) / 2.0;
  EXPECT_TRUE(blocked({0, 0, 1}, halfZ + 1.0));
  EXPECT_TRUE(blocked({0, 0, -1}, halfZ + 1.0));
  EXPECT_FALSE(blocked({1, 0, 0}, halfX + 3.0));
  EXPECT_FALSE(blocked({-1, 0, 0}, halfX + 3.0));
  EXPECT_TRUE(blocked({0, 1, 0}, plan_.hallCeiling - y + 1.0));
  EXPECT_TRUE(blocked({0, -1, 0}, 6.0));
}

TEST_F(WorldPlanTest, FlightWaypointsAreInTheOpenAirAndOneIsInTheHall) {
  ASSERT_GE(plan_.flight.size(), 4u);
  bool inHall = false;
  for (const glm::dvec3& p : plan_.flight) {
    for (const LayoutBox& b : plan_.boxes) EXPECT_FALSE(test::insideBox(b, p, 1.5));
    EXPECT_GT(p.y, field_->heightAt(p.x, p.z) + 3.0);
    inHall |= p.x > plan_.hallLo.x && p.x < plan_.hallHi.x && p.z > plan_.hallLo.y &&
              p.z < plan_.hallHi.y && p.y < plan_.hallCeiling;
  }
  EXPECT_TRUE(inHall);
}

}  // namespace
}  // namespace sdfstream
