#include "world/world.h"

#include <algorithm>
#include <climits>

namespace sdfstream {

glm::ivec3 World::indexMin() const {
  if (bricks.empty()) return glm::ivec3(0);
  glm::ivec3 m(INT_MAX);
  for (const Brick& b : bricks) m = glm::min(m, b.coord);
  return m * int(layout::kBrickCells);
}

glm::ivec3 World::indexMax() const {
  if (bricks.empty()) return glm::ivec3(0);
  glm::ivec3 m(INT_MIN);
  for (const Brick& b : bricks) m = glm::max(m, b.coord);
  return (m + 1) * int(layout::kBrickCells);
}

bool brickCoordLess(const glm::ivec3& a, const glm::ivec3& b) {
  if (a.z != b.z) return a.z < b.z;
  if (a.y != b.y) return a.y < b.y;
  return a.x < b.x;
}

}  // namespace sdfstream
