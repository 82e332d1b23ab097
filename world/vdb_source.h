// An OpenVDB float level set (.vdb) as an SdfSource (sdf_source.h).
#pragma once

#include <filesystem>
#include <memory>
#include <string>
#include <vector>

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

// One source per float level set of the file, in file order (readLevelSetGrids in
// level_set_bricks.h: labelled level sets and unlabelled look-alikes); the world is their union.
// Each behaves as makeVdbSource's grid: partitionFor takes v0 and the lattice from the first, and
// every grid whose transform is not that lattice is resampled onto it per LOD. Only the first
// names the material ("vdb grey"), so the manifest lists it once. Grids that are not float level
// sets, and level sets with no active voxel when others have some, are left out and described in
// *skipped ("'density' (fog volume)"). Errors: readLevelSetGrids's (NotLevelSet when the file has
// no float level set), Empty when every level set is empty, OutOfRange for a bad override.
std::vector<std::unique_ptr<SdfSource>> makeVdbSources(const std::filesystem::path& path,
                                                       double voxelOverride,
                                                       std::vector<std::string>* skipped);

}  // namespace sdfstream
