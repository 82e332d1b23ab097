// World partition: a world is a grid of independently loadable tiles, each holding
// 8³ bricks for LOD 0..L-1, where LOD l has voxel size v0·2^l. ARCHITECTURE.md "world/".
//
// Index spaces: LOD l's sample (i,j,k) sits at world position origin + v0·2^l·(i,j,k), so
// LOD l sample i coincides with LOD l-1 sample 2i (nested grids). Brick b of LOD l covers
// LOD-l cells [8b, 8b+8) (see shaders/shared/sdf_layout.h). Tile t covers LOD-0 cells
// [t·tileVoxels, (t+1)·tileVoxels), i.e. LOD-l bricks [t·n_l, (t+1)·n_l) with
// n_l = tileVoxels / (8·2^l); tileVoxels must be a multiple of 8·2^(L-1) so every LOD's bricks
// align with tile edges.
#pragma once

#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "world/world.h"

namespace sdfstream {

struct PartitionSpec {
  double voxelSize = 0.0;   // v0: LOD-0 voxel edge in metres
  int lodCount = 1;         // L >= 1, at most kMaxLods
  int tileVoxels = 0;       // tile edge in LOD-0 voxels; multiple of 8·2^(L-1)
  glm::dvec3 origin{0.0};   // world position of LOD-0 sample (0,0,0)

  static constexpr int kMaxLods = 8;
  double lodVoxelSize(int lod) const { return voxelSize * double(1 << lod); }
  double tileSizeMeters() const { return voxelSize * tileVoxels; }
  int tileBricks(int lod) const { return tileVoxels / (8 << lod); }  // bricks per tile edge
  bool valid() const;  // the rules above, voxelSize finite > 0
};

// Empty-space skipping data kept per tile and LOD: for each brick slot of the tile
// (n³ slots, x + n·(y + n·z), n = tileBricks(lod)) the Chebyshev distance in bricks to the
// nearest surface brick (0 = this slot holds a brick). It is computed over the tile plus a ring of
// kEmptyMargin bricks sampled from the neighbouring tiles' region, and every slot beyond that ring
// counts as occupied, so a value v promises no surface within (v-1)·8 voxels of any point of the
// slot, across tile borders too, without reading any other tile.
inline constexpr int kEmptyMargin = 1;

struct TileLod {
  std::vector<Brick> bricks;                // global LOD-l brick coords inside the tile, sorted
  std::vector<std::uint8_t> emptyDistance;  // n³ entries, see above
};

struct Tile {
  glm::ivec3 coord{0};
  std::vector<TileLod> lods;  // lodCount entries
};

// Tile containing a world position, and the world-space box of a tile.
glm::ivec3 tileOf(const PartitionSpec& spec, const glm::dvec3& world);
glm::dvec3 tileMin(const PartitionSpec& spec, glm::ivec3 tile);
glm::dvec3 tileMax(const PartitionSpec& spec, glm::ivec3 tile);

}  // namespace sdfstream
