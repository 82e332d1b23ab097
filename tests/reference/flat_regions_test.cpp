// flatRegionSpread: the largest plane of each view, and the luminance spread of the GI against the
// reference's over it.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "reference/flat_regions.h"

namespace sdfstream::reference {
namespace {

// One view: a 20 × 20 wall at z = 2 (normal +z), lit 1.0 by the reference and by a GI that is
// splotchy (blocks of 5 × 5 points at 0.8 and 1.2), and a smaller floor (10 × 10, y = 0) lit 3.0
// and 30.0 alternately by the GI, which must not be picked.
struct Scene {
  std::vector<glm::vec3> position, normal, gi, reference;
  std::vector<std::size_t> start{0};
};

Scene wallAndFloor() {
  Scene s;
  for (int y = 0; y < 20; ++y)
    for (int x = 0; x < 20; ++x) {
      s.position.push_back({0.1f * float(x), 0.1f * float(y), 2.0f});
      s.normal.push_back({0.0f, 0.0f, 1.0f});
      s.reference.push_back(glm::vec3(1.0f));
      s.gi.push_back(glm::vec3((x / 5 + y / 5) % 2 == 0 ? 0.8f : 1.2f));
    }
  for (int z = 0; z < 10; ++z)
    for (int x = 0; x < 10; ++x) {
      s.position.push_back({0.1f * float(x), 0.0f, 0.1f * float(z)});
      s.normal.push_back({0.0f, 1.0f, 0.0f});
      s.reference.push_back(glm::vec3(3.0f));
      s.gi.push_back(glm::vec3((x + z) % 2 == 0 ? 3.0f : 30.0f));
    }
  s.start.push_back(s.position.size());
  return s;
}

TEST(FlatRegionSpread, TheLargestPlaneOfAViewItsSplotchesAgainstTheReference) {
  const Scene s = wallAndFloor();
  const FlatSpread f = flatRegionSpread(s.position, s.normal, s.start, s.gi, s.reference, 0.01);
  EXPECT_EQ(f.regions, 1u);
  EXPECT_EQ(f.points, 400u);            // the wall, not the floor
  EXPECT_NEAR(f.gi, 0.2, 1e-6);         // 0.8 and 1.2 in equal shares around 1.0
  EXPECT_NEAR(f.reference, 0.0, 1e-9);  // the reference is flat there
  // The same GI as the reference: no excess spread.
  const FlatSpread same =
      flatRegionSpread(s.position, s.normal, s.start, s.reference, s.reference, 0.01);
  EXPECT_NEAR(same.gi, same.reference, 1e-12);
}

TEST(FlatRegionSpread, SmallViewsAndBadInput) {
  Scene s = wallAndFloor();
  // A second view of 10 points only: below minPoints, no region.
  for (int i = 0; i < 10; ++i) {
    s.position.push_back({float(i), 0.0f, 0.0f});
    s.normal.push_back({0.0f, 1.0f, 0.0f});
    s.gi.push_back(glm::vec3(1.0f));
    s.reference.push_back(glm::vec3(1.0f));
  }
  s.start.push_back(s.position.size());
  const FlatSpread f = flatRegionSpread(s.position, s.normal, s.start, s.gi, s.reference, 0.01);
  EXPECT_EQ(f.regions, 1u);
  std::vector<glm::vec3> shorter(s.gi.begin(), s.gi.end() - 1);
  EXPECT_THROW(flatRegionSpread(s.position, s.normal, s.start, shorter, s.reference, 0.01),
               std::invalid_argument);
}

}  // namespace
}  // namespace sdfstream::reference
