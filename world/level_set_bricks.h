// The bricking step shared by mesh and .vdb import: an OpenVDB float level set (values in world
// units, uniform voxel size) → the World's 8³ bricks. Internal to world/ (includes OpenVDB).
#pragma once

#include <functional>

#include <openvdb/openvdb.h>

#include "world/world.h"

namespace sdfstream {

// Fills brick.albedo / brick.emission for a brick whose coord and distances are set. Called
// concurrently from several threads, once per kept brick; must be deterministic per brick.
using BrickMaterialFn = std::function<void(Brick&)>;

// One brick per OpenVDB leaf (leaves are 8³ at multiples of 8, exactly our bricks: ARCHITECTURE.md
// "Brick"; coord = leaf origin / 8), plus bricks whose apron reaches into a leaf and bricks inside
// active tiles. A brick is kept iff one of its 9³ samples has |d| < kNarrowBand voxels, so every
// cell with a sign change has its brick. Samples are value / voxelSize clamped to ±kNarrowBand
// (non-finite values read as +kNarrowBand). Output sorted by brickCoordLess, independent of
// thread scheduling. World::origin is the world position of index (0,0,0) of grid's transform,
// which must be linear with uniform scale and no rotation (asserted by callers).
World bricksFromLevelSet(const openvdb::FloatGrid& grid, const BrickMaterialFn& material);

// Rough peak bytes per narrow-band voxel while building: the float distance and int32 index
// trees, OpenVDB's scratch trees during mesh conversion, partially filled leaves and the output
// bricks. Deliberately conservative.
inline constexpr double kBytesPerBandVoxel = 48.0;

}  // namespace sdfstream
