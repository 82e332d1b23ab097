#include "world/level_set_bricks.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <glm/gtc/packing.hpp>

namespace sdfstream {
namespace {

constexpr int kCells = int(layout::kBrickCells);
constexpr int kSamples = int(layout::kBrickSamples);

glm::ivec3 floorDiv8(const openvdb::Coord& c) { return {c.x() >> 3, c.y() >> 3, c.z() >> 3}; }

struct CoordLess {
  bool operator()(const glm::ivec3& a, const glm::ivec3& b) const { return brickCoordLess(a, b); }
};

// A level-set value (world units) as a stored sample: voxel units, clamped to the narrow band;
// non-finite values read as far outside. A level set keeps "beyond the band" as band × voxel in
// world units, which need not come back as the band exactly: an open mesh's shifted background
// at 0.05 m voxels reads 2.99999976 (a third of voxel sizes from 1 cm to 2 m do so). Taken for a
// distance just inside the band, every brick its blocks touched was stored, full of nothing
// (72% of Sponza's LOD-0 bricks), and the coarse LODs' min-filter made a surface 1.5 voxels away
// of each such sample (74% of LOD-1 samples). So values within kBandSnap of the band are the band.
// In voxels: half fp16's step at 3, so the stored value was 3 anyway.
constexpr float kBandSnap = 1e-3f;

float bandVoxels(float value, float invVoxel) {
  const float d = value * invVoxel;
  if (!std::isfinite(d)) return layout::kNarrowBand;
  if (std::abs(d) >= layout::kNarrowBand - kBandSnap) return std::copysign(layout::kNarrowBand, d);
  return d;
}

// Fills brick's coord and distances; returns whether any sample is inside the narrow band.
bool sampleBrick(openvdb::FloatGrid::ConstAccessor& acc, glm::ivec3 coord, float invVoxel,
                 Brick& brick) {
  brick.coord = coord;
  const openvdb::Coord base(coord.x * kCells, coord.y * kCells, coord.z * kCells);
  bool near = false;
  for (int z = 0; z < kSamples; ++z)
    for (int y = 0; y < kSamples; ++y)
      for (int x = 0; x < kSamples; ++x) {
        const float d = bandVoxels(acc.getValue(base.offsetBy(x, y, z)), invVoxel);
        near = near || std::abs(d) < layout::kNarrowBand;
        brick.distance[brickSampleIndex(x, y, z)] = std::uint16_t(glm::packHalf1x16(d));
      }
  return near;
}

}  // namespace

World bricksFromLevelSet(const openvdb::FloatGrid& grid, const BrickMaterialFn& material) {
  static_assert(openvdb::FloatTree::LeafNodeType::DIM == layout::kBrickCells,
                "OpenVDB leaves must be our bricks");
  const double voxelSize = grid.voxelSize()[0];
  const openvdb::Vec3d origin = grid.transform().indexToWorld(openvdb::Vec3d(0.0));

  // Candidate bricks: each leaf's own brick and the 7 bricks below it whose apron samples
  // (index 8b+8) lie in this leaf.
  std::vector<glm::ivec3> candidates;
  candidates.reserve(grid.tree().leafCount() * 2);
  for (auto leaf = grid.tree().cbeginLeaf(); leaf; ++leaf) {
    glm::ivec3 b = floorDiv8(leaf->origin());
    for (int dz = 0; dz <= 1; ++dz)
      for (int dy = 0; dy <= 1; ++dy)
        for (int dx = 0; dx <= 1; ++dx) candidates.push_back(b - glm::ivec3(dx, dy, dz));
  }
  // Active tiles (coarser than a leaf) near the surface: every brick they cover, plus apron.
  for (auto it = grid.cbeginValueOn(); it; ++it) {
    if (!it.isTileValue() || !(std::abs(bandVoxels(*it, 1.0f / voxelSize)) < layout::kNarrowBand))
      continue;
    openvdb::CoordBBox box;
    it.getBoundingBox(box);
    glm::ivec3 lo = floorDiv8(box.min()) - 1, hi = floorDiv8(box.max());
    for (int z = lo.z; z <= hi.z; ++z)
      for (int y = lo.y; y <= hi.y; ++y)
        for (int x = lo.x; x <= hi.x; ++x) candidates.push_back({x, y, z});
  }
  std::sort(candidates.begin(), candidates.end(), CoordLess{});
  candidates.erase(std::unique(candidates.begin(), candidates.end()), candidates.end());

  World world;
  world.voxelSize = voxelSize;
  world.origin = glm::dvec3(origin.x(), origin.y(), origin.z());

  // Chunks bound the scratch memory (a brick is ~5.5 KB; candidates outnumber kept bricks).
  constexpr std::size_t kChunk = 8192;
  std::vector<Brick> chunk(std::min(kChunk, candidates.size()));
  std::vector<char> keep(chunk.size());
  const float invVoxel = float(1.0 / voxelSize);
  for (std::size_t first = 0; first < candidates.size(); first += kChunk) {
    const std::size_t count = std::min(kChunk, candidates.size() - first);
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, count, 16),
                      [&](const tbb::blocked_range<std::size_t>& range) {
                        auto acc = grid.getConstAccessor();
                        for (std::size_t i = range.begin(); i != range.end(); ++i)
                          keep[i] = sampleBrick(acc, candidates[first + i], invVoxel, chunk[i]);
                        for (std::size_t i = range.begin(); i != range.end(); ++i)
                          if (keep[i]) material(chunk[i]);
                      });
    for (std::size_t i = 0; i < count; ++i)
      if (keep[i]) world.bricks.push_back(chunk[i]);
  }
  return world;
}

bool unionLevelSetBrick(openvdb::FloatGrid::ConstAccessor& acc, glm::ivec3 brick, float voxelSize,
                        BrickSamples& out, std::array<float, layout::kBrickSampleCount>* own) {
  const openvdb::Coord base(brick.x * kCells, brick.y * kCells, brick.z * kCells);
  const float invVoxel = 1.0f / voxelSize;
  // Samples 8b..8b+8 lie in the leaf at 8b and (apron) its + neighbours. Without any leaf there,
  // each of those 8 leaf-sized blocks holds one tile or background value (voxel units here).
  bool anyLeaf = false, allFar = true;
  float block[8];
  for (int corner = 0; corner < 8 && !anyLeaf; ++corner) {
    const openvdb::Coord c =
        base.offsetBy(corner & 1 ? kCells : 0, corner & 2 ? kCells : 0, corner & 4 ? kCells : 0);
    if (acc.probeConstLeaf(c)) {
      anyLeaf = true;
    } else {
      block[corner] = bandVoxels(acc.getValue(c), invVoxel);
      if (!(block[corner] >= layout::kNarrowBand)) allFar = false;
    }
  }
  if (!anyLeaf && allFar) return false;
  if (!anyLeaf) {  // constant blocks (e.g. deep inside): no per-sample tree walk
    bool near = false;
    for (int z = 0; z < kSamples; ++z)
      for (int y = 0; y < kSamples; ++y)
        for (int x = 0; x < kSamples; ++x) {
          const int corner = (x >= kCells) | (y >= kCells) << 1 | (z >= kCells) << 2;
          const float d = block[corner];
          near = near || std::abs(d) < layout::kNarrowBand;
          const std::size_t i = std::size_t(brickSampleIndex(x, y, z));
          if (own) (*own)[i] = d;
          out.distance[i] = std::min(out.distance[i], d);
        }
    return near;
  }
  bool near = false;
  for (int z = 0; z < kSamples; ++z)
    for (int y = 0; y < kSamples; ++y)
      for (int x = 0; x < kSamples; ++x) {
        const float d = bandVoxels(acc.getValue(base.offsetBy(x, y, z)), invVoxel);
        near = near || std::abs(d) < layout::kNarrowBand;
        const int i = brickSampleIndex(x, y, z);
        if (own) (*own)[std::size_t(i)] = d;
        out.distance[std::size_t(i)] = std::min(out.distance[std::size_t(i)], d);
      }
  return near;
}

}  // namespace sdfstream
