// The generated world's showcase flight (world/world_plan.h) as the fly-through flies it
// (demo/fly_path.h's spline, not just its waypoints): clear of every building, lamp and road slab
// by a metre, above the terrain and the trees, and through the hall from door to door under its
// roof.
#include <gtest/gtest.h>

#include "demo/fly_path.h"
#include "tests/support/generated_world.h"

namespace sdfstream {
namespace {

TEST(ShowcaseFlight, ClearsEveryBoxAndTheGroundAndCrossesTheHall) {
  SDFSTREAM_REQUIRE_WORLD_PACKAGES();
  const test::GeneratedPlan g = test::generatedPlan("showcase-flight");
  const FlyPath path{g.plan.flight};
  const double length = path.length();
  ASSERT_GT(length, 500.0);
  double hallMetres = 0.0, lowest = 1e9;
  const WorldPlan& plan = g.plan;
  for (double s = 0.0; s <= length; s += 0.5) {
    const glm::dvec3 p = path.position(s);
    for (const LayoutBox& b : plan.boxes)
      ASSERT_FALSE(test::insideBox(b, p, 1.0)) << "at " << s << " m the camera (" << p.x << ", "
                                               << p.y << ", " << p.z << ") is within 1 m of a box";
    lowest = std::min(lowest, p.y - g.terrain->heightAt(p.x, p.z));
    const bool inHall =
        p.x > plan.hallLo.x && p.x < plan.hallHi.x && p.z > plan.hallLo.y && p.z < plan.hallHi.y;
    if (inHall) {
      EXPECT_LT(p.y, plan.hallCeiling - 2.0);
      hallMetres += 0.5;
    }
  }
  EXPECT_GT(lowest, 2.5);
  // Nor through a tree: where the camera passes within a tree's crown (its size / 2 plus a metre,
  // horizontally), it is above the treetop.
  for (double s = 0.0; s <= length; s += 1.0) {
    const glm::dvec3 p = path.position(s);
    for (const PlannedAsset& a : plan.assets) {
      if (a.kind != PlanAsset::Conifer && a.kind != PlanAsset::Broadleaf) continue;
      if (glm::length(glm::dvec2(p.x, p.z) - a.at) > a.size / 2.0 + 1.0) continue;
      ASSERT_GT(p.y, g.terrain->heightAt(a.at.x, a.at.y) + a.size + 1.0)
          << "at " << s << " m the camera flies through a " << a.size << " m tree";
    }
  }
  // The hall is 52 m long: the flight crosses all of it.
  EXPECT_GT(hallMetres, 0.9 * (plan.hallHi.x - plan.hallLo.x));
}

}  // namespace
}  // namespace sdfstream
