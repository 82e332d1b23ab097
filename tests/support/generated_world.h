// The generated world's plan on the real terrain, for tests of world/world_plan.h and of the
// showcase flight: both need trigger-rally-data and sweethome3d-furniture (scripts/setup).
#pragma once

#include <filesystem>
#include <memory>

#include "tests/support/test_data.h"
#include "world/generate_world.h"
#include "world/scene_layout.h"
#include "world/world_plan.h"

namespace sdfstream::test {

inline bool worldPackagesPresent() {
  return std::filesystem::exists("/usr/share/games/trigger-rally/data.zip") &&
         std::filesystem::exists("/usr/share/sweethome3d/furniture/Scopia.sh3f");
}

// The default 4 km world's terrain (generate-world's stretch of trigger-rally's map) and plan.
struct GeneratedPlan {
  std::unique_ptr<Heightfield> terrain;
  WorldPlan plan;
};

inline GeneratedPlan generatedPlan(const std::string& scratch) {
  GenerateWorldOptions o;
  o.dir = scratchDir(scratch);
  o.settlements = false;  // only the terrain is wanted: the plan is made here
  generateWorld(o);
  GeneratedPlan g;
  g.terrain =
      std::make_unique<Heightfield>(Heightfield::load(*parseLayout(o.dir / "layout.json").terrain));
  g.plan = planWorld(*g.terrain, o.sizeKm * 1000.0, std::uint64_t(o.seed));
  return g;
}

inline bool insideBox(const LayoutBox& b, const glm::dvec3& p, double grow) {
  return p.x > b.min.x - grow && p.x < b.max.x + grow && p.y > b.min.y - grow &&
         p.y < b.max.y + grow && p.z > b.min.z - grow && p.z < b.max.z + grow;
}

}  // namespace sdfstream::test

#define SDFSTREAM_REQUIRE_WORLD_PACKAGES()                                                     \
  do {                                                                                         \
    if (!::sdfstream::test::worldPackagesPresent())                                            \
      GTEST_SKIP() << "skipped: trigger-rally-data or sweethome3d-furniture is not installed " \
                      "(scripts/setup installs both)";                                         \
  } while (0)
