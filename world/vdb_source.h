// An OpenVDB float level set (.vdb) as an SdfSource (sdf_source.h).
#pragma once

#include <filesystem>
#include <memory>

#include "world/sdf_source.h"

namespace sdfstream {

// Reads the grid vdbToWorld would import (grid choice, untrusted-input safety and errors of
// vdb_import.h: Io, Truncated, NotLevelSet, OutOfRange for a bad override) at construction.
// nativeVoxelSize = voxelOverride if > 0, else the grid's voxel size; nativeOrigin = the grid's
// index-0 world position (so a default spec keeps the grid's lattice).
// prepareLod(spec, l): when the grid's transform is uniform, axis-aligned, of voxel
// spec.lodVoxelSize(l) and its lattice coincides with the spec's, the grid is used as is (LOD 0
// of a plain import reproduces the file's values exactly, up to fp16); otherwise it is rebuilt
// onto the aligned grid of voxel v_l by tools::resampleToMatch (a level-set rebuild: re-normalised
// distances, band kNarrowBand LOD-l voxels). Materials: grey albedo 0.8 (linear), no emission.
// Throws InputError(Empty) when the grid has no active voxel.
std::unique_ptr<SdfSource> makeVdbSource(const std::filesystem::path& path, double voxelOverride);

}  // namespace sdfstream
