#include "world/world_io.h"

#include <algorithm>
#include <map>
#include <unordered_set>
#include <vector>

#include "world/pack.h"

namespace sdfstream {
namespace {

int floorDiv(int a, int b) { return a / b - ((a % b != 0) && ((a < 0) != (b < 0))); }

struct CoordHash {
  std::size_t operator()(const glm::ivec3& c) const {
    return std::size_t(c.x) * 73856093u ^ std::size_t(c.y) * 19349663u ^
           std::size_t(c.z) * 83492791u;
  }
};

// partition.h's emptyDistance for one tile: exact Chebyshev distance transform (two raster
// passes over the 26-neighbourhood) on the tile plus a ring of kEmptyMargin bricks, inside a
// layer that counts as occupied.
std::vector<std::uint8_t> emptyDistance(glm::ivec3 tile, int n,
                                        const std::unordered_set<glm::ivec3, CoordHash>& bricks) {
  const int pad = kEmptyMargin + 1, g = n + 2 * pad;
  constexpr int kFar = 1 << 20;
  std::vector<int> d(std::size_t(g) * g * g);
  auto at = [&](int x, int y, int z) -> int& { return d[std::size_t(x + g * (y + g * z))]; };
  const glm::ivec3 base = tile * n - pad;
  for (int z = 0; z < g; ++z)
    for (int y = 0; y < g; ++y)
      for (int x = 0; x < g; ++x) {
        const bool outer = x == 0 || y == 0 || z == 0 || x == g - 1 || y == g - 1 || z == g - 1;
        at(x, y, z) = outer || bricks.count(base + glm::ivec3(x, y, z)) ? 0 : kFar;
      }
  auto pass = [&](int sign) {
    for (int zi = 1; zi < g - 1; ++zi)
      for (int yi = 1; yi < g - 1; ++yi)
        for (int xi = 1; xi < g - 1; ++xi) {
          const int x = sign > 0 ? xi : g - 1 - xi, y = sign > 0 ? yi : g - 1 - yi,
                    z = sign > 0 ? zi : g - 1 - zi;
          int best = at(x, y, z);
          // The 13 neighbours already visited in this scan order.
          for (int dz = -1; dz <= 0; ++dz)
            for (int dy = -1; dy <= 1; ++dy)
              for (int dx = -1; dx <= 1; ++dx) {
                if (dz == 0 && (dy > 0 || (dy == 0 && dx >= 0))) continue;
                best = std::min(best, at(x + sign * dx, y + sign * dy, z + sign * dz) + 1);
              }
          at(x, y, z) = best;
        }
  };
  pass(+1);
  pass(-1);
  std::vector<std::uint8_t> out(std::size_t(n) * n * n);
  for (int z = 0; z < n; ++z)
    for (int y = 0; y < n; ++y)
      for (int x = 0; x < n; ++x)
        out[std::size_t(x + n * (y + n * z))] =
            std::uint8_t(std::min(at(x + pad, y + pad, z + pad), 255));
  return out;
}

}  // namespace

void writeWorld(const World& world, const std::filesystem::path& dir) {
  PartitionSpec spec;
  spec.voxelSize = world.voxelSize;
  spec.origin = world.origin;
  spec.lodCount = 1;
  spec.tileVoxels = kWorldTileVoxels;
  const int n = spec.tileBricks(0);

  // Bricks grouped by tile; World order is (z, y, x), which each group keeps.
  auto tileLess = [](const glm::ivec3& a, const glm::ivec3& b) { return brickCoordLess(a, b); };
  std::map<glm::ivec3, std::vector<const Brick*>, decltype(tileLess)> tiles(tileLess);
  std::unordered_set<glm::ivec3, CoordHash> occupied;
  occupied.reserve(world.bricks.size());
  for (const Brick& b : world.bricks) {
    const glm::ivec3 t(floorDiv(b.coord.x, n), floorDiv(b.coord.y, n), floorDiv(b.coord.z, n));
    tiles[t].push_back(&b);
    occupied.insert(b.coord);
  }

  PackWriter writer(dir, spec);
  for (const auto& [coord, bricks] : tiles) {
    Tile tile;
    tile.coord = coord;
    tile.lods.resize(1);
    tile.lods[0].bricks.reserve(bricks.size());
    for (const Brick* b : bricks) tile.lods[0].bricks.push_back(*b);
    tile.lods[0].emptyDistance = emptyDistance(coord, n, occupied);
    writer.addTile(tile);
  }
  writer.commit(world.worldMin(), world.worldMax(), world.source, {});
}

World readWorld(const std::filesystem::path& dir) { return loadLod(dir, 0); }

}  // namespace sdfstream
