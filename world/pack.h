// The world pack (issue 3): a directory with manifest.json and one file per tile, written
// atomically, every section checksummed, brick payloads zstd-compressed.
//
//   WORLD/manifest.json   format "sdfstream-pack", version, PartitionSpec, bounds, source,
//                         materials, objectLibrary (empty for now), and per tile: coord, file
//                         name, byte size, xxh3 checksum, bricks per LOD
//   WORLD/tiles/<x>_<y>_<z>.tile
//
// Identical input gives byte-identical packs (no timestamps, tiles sorted, fixed JSON format).
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "world/partition.h"
#include "world/world.h"

namespace sdfstream {

struct TileEntry {
  glm::ivec3 coord{0};
  std::string file;                   // relative to the pack directory
  std::uint64_t bytes = 0;
  std::uint64_t checksum = 0;         // xxh3 of the whole tile file
  std::vector<std::uint32_t> bricksPerLod;
};

struct PackManifest {
  PartitionSpec spec;
  glm::dvec3 boundsMin{0.0}, boundsMax{0.0};  // world-space bounds of the surface
  std::string source;                         // input file name(s)
  std::vector<std::string> materials;         // material names, informational
  std::vector<TileEntry> tiles;               // sorted by coord (z, y, x)
};

// Writes a pack: tiles may be added from several threads; nothing is visible at `dir` until
// commit(), which writes the manifest and renames the staging directory into place (an
// existing pack survives any failure). Tiles with no brick at any LOD are not stored.
class PackWriter {
 public:
  PackWriter(const std::filesystem::path& dir, const PartitionSpec& spec);
  ~PackWriter();
  void addTile(const Tile& tile);  // thread-safe; throws InputError(Io) on write failure
  void commit(glm::dvec3 boundsMin, glm::dvec3 boundsMax, const std::string& source,
              const std::vector<std::string>& materials);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

PackManifest readManifest(const std::filesystem::path& dir);
// Reads and verifies one tile (checksums, sizes, version). InputError names the tile file.
Tile readTile(const std::filesystem::path& dir, const TileEntry& entry, int lodCount);

// Checks every checksum; returns an empty string when all is well, else the first problem as
// one line naming the bad tile.
std::string verifyPack(const std::filesystem::path& dir);

// All bricks of one LOD from every tile, as a World in that LOD's index space
// (voxelSize = v0·2^lod, origin = spec.origin). Used by render until streaming reads tiles.
World loadLod(const std::filesystem::path& dir, int lod);

// Joins packs imported with --shard i/n (same spec, disjoint tiles) into one pack at `out`.
void mergePacks(const std::vector<std::filesystem::path>& shards, const std::filesystem::path& out);

}  // namespace sdfstream
