// OpenVDB level set (.vdb) → World.
#pragma once

#include <filesystem>

#include "world/import_limits.h"
#include "world/world.h"

namespace sdfstream {

// Imports the first float level set of a .vdb file. Grid choice: the first FloatGrid whose class
// is GRID_LEVEL_SET; failing that, the first FloatGrid with no class (GRID_UNKNOWN) that looks
// like an unlabelled level set (older tools write them without a class): a positive background
// (OpenVDB level sets store +half-width outside), at least one negative active value, and a
// linear transform with uniform scale. A fog volume (background 0, values >= 0) never qualifies.
//
// Transform: a linear transform with uniform scale and translation only is honoured exactly
// (World::origin = world position of index 0, voxelSize = scale). Any other transform (rotation,
// non-uniform scale, frustum), or voxelSizeOverride > 0, resamples the level set onto an
// axis-aligned grid with origin (0,0,0) via tools::resampleToMatch (a level-set rebuild, so the
// result is re-normalised). Distances stored = value / voxelSize clamped to ±kNarrowBand (the
// file's own band may be narrower: those bricks then saturate at the file's background).
// Materials: grey albedo 0.8 (linear), no emission.
//
// Safe on untrusted input (OpenVDB's reader behind exception handling). Errors (InputError):
// Io (missing/unreadable), Truncated (file shorter than declared or corrupt), NotLevelSet (names
// what the file holds), Empty (no voxel within the band), TooLarge (estimate above limits),
// OutOfRange (bad override).
World vdbToWorld(const std::filesystem::path& file, double voxelSizeOverride,
                 const ImportLimits& limits);

}  // namespace sdfstream
