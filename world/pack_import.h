// The tiled world importer: SdfSources → a world pack (pack.h) of multi-LOD tiles
// (tile_builder.h), in parallel, optionally one shard of the tiles.
#pragma once

#include <cstddef>
#include <filesystem>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "world/import_limits.h"
#include "world/partition.h"
#include "world/sdf_source.h"

namespace sdfstream {

struct PackImportOptions {
  double voxelSize = 0;  // v0 in metres; 0 = the first source's nativeVoxelSize
  int lodCount = 4;
  int tileVoxels = 128;  // tile edge in LOD-0 voxels (multiple of 8·2^(lodCount-1))
  ImportLimits limits;
  int shardIndex = 0, shardCount = 1;  // build tiles whose rank in sorted order % count == index
  // Called after each finished tile from the thread that built it, serialized (never two at once);
  // total = the tiles this shard builds.
  std::function<void(std::size_t done, std::size_t total)> progress;
};

// The input file's sources by extension (case-insensitive): .gltf/.glb/.obj → one mesh source
// (mesh_source.h); .vdb → one vdb source per float level set of the file, their union being the
// world (makeVdbSources in vdb_source.h, voxelSize as their override; v0 and the lattice from the
// first grid unless overridden); grids that are not float level sets are skipped with one line on
// stderr naming the file and them; .json → the layout's sources (layout_sources.h: terrain, one
// mesh per placement, boxes). Errors: those of the loaders, InputError(Usage) for an unknown
// extension.
std::vector<std::unique_ptr<SdfSource>> sourcesForInput(const std::filesystem::path& input,
                                                        double voxelSize,
                                                        const ImportLimits& limits);

// The partition for these sources and options: v0 = options.voxelSize or the first source's
// nativeVoxelSize (mesh: defaultVoxelSize; .vdb: the grid's own), origin = that source's
// nativeOrigin when v0 is its native voxel (keeps a .vdb's lattice), else (0,0,0).
// Throws InputError(OutOfRange) if the result breaks partition.h's rules.
PartitionSpec partitionFor(const std::vector<std::unique_ptr<SdfSource>>& sources,
                           const PackImportOptions& options, const std::string& sourceName);

// The tiles importPack would consider: every tile overlapping the union of the sources' bounds
// grown by the coarsest LOD's band plus one voxel, sorted (z, y, x).
std::vector<glm::ivec3> candidateTiles(const std::vector<std::unique_ptr<SdfSource>>& sources,
                                       const PartitionSpec& spec);

// Builds the pack at `out` (atomic: PackWriter). Steps: refuse with InputError(TooLarge) when the
// sum of the sources' estimateBytes exceeds options.limits.maxBytes (before any work); prepareLod
// for every LOD of every source, all (source, LOD) pairs in parallel (all LODs stay resident: buildTile filters each tile's LOD chain
// in one go); build this shard's tiles in parallel (TBB), each added to the writer as it finishes;
// releaseLod; commit with the union of the sources' bounds (the same in every shard) and
// sourceName. Deterministic: same sources, spec and shard → byte-identical pack. Throws
// InputError (Usage for a bad shard or spec, TooLarge, Io from the writer) or the sources' errors.
void importPack(const std::vector<std::unique_ptr<SdfSource>>& sources,
                const std::filesystem::path& out, const PartitionSpec& spec,
                const PackImportOptions& options, const std::string& sourceName);

}  // namespace sdfstream
