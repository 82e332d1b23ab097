// The world pack: a directory with manifest.json and one file per tile, written
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
#include "world/scene_lights.h"
#include "world/world.h"

namespace sdfstream {

struct TileEntry {
  glm::ivec3 coord{0};
  std::string file;  // relative to the pack directory
  std::uint64_t bytes = 0;
  std::uint64_t checksum = 0;  // xxh3 of the whole tile file
  std::vector<std::uint32_t> bricksPerLod;
};

struct PackManifest {
  PartitionSpec spec;
  glm::dvec3 boundsMin{0.0}, boundsMax{0.0};  // world-space bounds of the surface
  std::string source;                         // input file name(s)
  std::vector<std::string> materials;         // material names, informational
  std::vector<SceneLight> lights;             // the sources' own lights, world space (optional)
  std::vector<TileEntry> tiles;               // sorted by coord (z, y, x)
};

// Writes a pack: tiles may be added from several threads, in any order; nothing is visible at
// `dir` until commit(), which writes the manifest and renames the staging directory
// ("<dir>.tmp-*", beside dir) into place (an existing pack survives any failure, and the
// destructor removes the staging directory unless commit() succeeded). Each tile is compressed
// and written as it comes (memory: one tile per calling thread). Tiles with no brick at any LOD
// are not stored. The file bytes depend only on the tiles and commit()'s arguments.
// Test hook: SDFSTREAM_FAIL_WRITE_AFTER_BYTES=N makes writes fail as on a full disk after N bytes.
class PackWriter {
 public:
  // Throws InputError(Usage) if the spec breaks partition.h's rules, (Io) if staging fails.
  PackWriter(const std::filesystem::path& dir, const PartitionSpec& spec);
  ~PackWriter();
  // Thread-safe. The tile must have spec.lodCount LODs, bricks sorted and inside the tile,
  // emptyDistance of n³ with 0 at brick slots, and a coordinate not added before
  // (std::invalid_argument otherwise). Throws InputError(Io) on write failure; after one,
  // commit() refuses.
  void addTile(const Tile& tile);
  // Call once, after every addTile has returned.
  void commit(glm::dvec3 boundsMin, glm::dvec3 boundsMax, const std::string& source,
              const std::vector<std::string>& materials,
              const std::vector<SceneLight>& lights = {});

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// Reading is safe on untrusted input: every size is bounded before allocating (limits in
// pack_format.h) and every error is an InputError naming the file (and, for the manifest, the
// key): Io (missing/unreadable), Malformed, Version, Truncated, Checksum, NonFinite, OutOfRange,
// TooLarge. All functions below are thread-safe (they share no state).

// Parses and checks manifest.json (format, version, spec rules, tile names, sorted tiles).
PackManifest readManifest(const std::filesystem::path& dir);
// Reads and verifies one tile: size and whole-file xxh3 against the entry, header, section
// checksums, decompressed sizes, bricks sorted and inside the tile, emptyDistance n³.
// Checks the tile's edge against spec.tileVoxels too.
Tile readTile(const std::filesystem::path& dir, const TileEntry& entry, const PartitionSpec& spec);
// The same checks, with the tile edge taken from the tile itself (its LOD-0 emptyDistance is n³)
// instead of the manifest: for callers that keep only lodCount. Prefer the overload above.
Tile readTile(const std::filesystem::path& dir, const TileEntry& entry, int lodCount);

// Reads one LOD of a tile for streaming: verifies the size against the manifest, the header and
// that LOD's section checksum and contents, and decodes only that section (the returned tile's
// other LODs are empty). The whole-file checksum is left to verifyPack: every byte this uses is
// covered by the header or the section checksum.
// Only the header and that section are read from disk; *bytesRead (optional) receives how many.
Tile readTileLod(const std::filesystem::path& dir, const TileEntry& entry,
                 const PartitionSpec& spec, int lod, std::size_t* bytesRead = nullptr);

// Checks the manifest and fully reads every tile (in parallel); returns an empty string when all
// is well, else the first problem in manifest order as one line naming the bad tile, e.g.
// "tiles/0_0_1.tile: section lod2 checksum mismatch".
std::string verifyPack(const std::filesystem::path& dir);

// All bricks of one LOD from every tile, as a World in that LOD's index space
// (voxelSize = v0·2^lod, origin = spec.origin, bricks sorted and unique, source from the
// manifest). Used by render until streaming reads tiles. Memory: the whole LOD.
World loadLod(const std::filesystem::path& dir, int lod);

// Joins packs imported with --shard i/n into one pack at `out` (atomically, like PackWriter).
// The shards must have the same partition, source and materials (else InputError(Malformed)
// naming the shard) and disjoint tiles (else InputError(Malformed) naming the tile). Tile files
// are verified and copied byte for byte and the manifest is written exactly as PackWriter would,
// so merging the shards of an import gives the same bytes as the one-shot import.
void mergePacks(const std::vector<std::filesystem::path>& shards, const std::filesystem::path& out);

}  // namespace sdfstream
