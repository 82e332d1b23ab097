// CPU trilinear sampling of a World's bricks: the reference for tests and tools (the trace shader
// does the same math on the atlas). Construction indexes the bricks by coordinate (O(n) memory);
// sampling is read-only and thread-safe.
#pragma once

#include <cmath>
#include <optional>
#include <unordered_map>

#include <glm/glm.hpp>
#include <glm/gtc/packing.hpp>

#include "world/world.h"

namespace sdfstream {

class BrickSampler {
 public:
  explicit BrickSampler(const World& world) : world_(world) {
    index_.reserve(world.bricks.size());
    for (std::size_t i = 0; i < world.bricks.size(); ++i) index_[key(world.bricks[i].coord)] = i;
  }

  // Signed distance in voxels at a world position, trilinear over the 8 samples around it (all in
  // one brick thanks to the apron, sdf_layout.h). nullopt when no brick covers the point: it is
  // then at least about kNarrowBand voxels from any surface.
  std::optional<float> distanceVoxels(glm::dvec3 worldPos) const {
    glm::dvec3 p = (worldPos - world_.origin) / world_.voxelSize;  // index space
    glm::dvec3 cell = glm::floor(p);
    glm::ivec3 c(cell);
    glm::ivec3 b(floorDiv(c.x), floorDiv(c.y), floorDiv(c.z));
    auto it = index_.find(key(b));
    if (it == index_.end()) return std::nullopt;
    const Brick& brick = world_.bricks[it->second];
    glm::ivec3 l = c - b * int(layout::kBrickCells);  // 0..7
    glm::vec3 f(p - cell);
    auto s = [&](int dx, int dy, int dz) {
      return glm::unpackHalf1x16(brick.distance[brickSampleIndex(l.x + dx, l.y + dy, l.z + dz)]);
    };
    float x00 = glm::mix(s(0, 0, 0), s(1, 0, 0), f.x), x10 = glm::mix(s(0, 1, 0), s(1, 1, 0), f.x);
    float x01 = glm::mix(s(0, 0, 1), s(1, 0, 1), f.x), x11 = glm::mix(s(0, 1, 1), s(1, 1, 1), f.x);
    return glm::mix(glm::mix(x00, x10, f.y), glm::mix(x01, x11, f.y), f.z);
  }

  // The brick holding index cell (i,j,k), or nullptr.
  const Brick* brickAtCell(glm::ivec3 cell) const {
    auto it = index_.find(key({floorDiv(cell.x), floorDiv(cell.y), floorDiv(cell.z)}));
    return it == index_.end() ? nullptr : &world_.bricks[it->second];
  }

 private:
  static_assert(layout::kBrickCells == 8);
  static int floorDiv(int v) { return v >> 3; }  // arithmetic shift = floor(v / 8)
  static std::uint64_t key(glm::ivec3 c) {
    return (std::uint64_t(std::uint32_t(c.x) & 0x1fffff)) |
           (std::uint64_t(std::uint32_t(c.y) & 0x1fffff) << 21) |
           (std::uint64_t(std::uint32_t(c.z) & 0x1fffff) << 42);
  }
  const World& world_;
  std::unordered_map<std::uint64_t, std::size_t> index_;
};

}  // namespace sdfstream
