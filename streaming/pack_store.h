// A TileStore reading a world pack on disk (world/pack.h): the manifest is read once; tiles are
// read, checksum-verified and decompressed on the loader's worker threads.
#pragma once

#include <filesystem>
#include <map>
#include <memory>

#include "streaming/tile_loader.h"
#include "streaming/tile_store.h"
#include "world/pack.h"

namespace sdfstream {

class PackTileStore : public TileStore {
 public:
  // Throws InputError when the manifest is missing or malformed.
  explicit PackTileStore(std::filesystem::path dir);

  const PartitionSpec& spec() const override { return manifest_.spec; }
  bool hasTile(glm::ivec3 tile) const override { return entries_.count(tile) != 0; }
  std::shared_ptr<const Tile> load(glm::ivec3 tile, int lod, std::size_t* bytesRead) const override;
  const PackManifest& manifest() const { return manifest_; }

 private:
  std::filesystem::path dir_;
  PackManifest manifest_;
  std::map<glm::ivec3, const TileEntry*, IVec3Less> entries_;
};

}  // namespace sdfstream
