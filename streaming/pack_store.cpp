#include "streaming/pack_store.h"

namespace sdfstream {

PackTileStore::PackTileStore(std::filesystem::path dir)
    : dir_(std::move(dir)), manifest_(readManifest(dir_)) {
  for (const TileEntry& e : manifest_.tiles) entries_[e.coord] = &e;
}

std::shared_ptr<const Tile> PackTileStore::load(glm::ivec3 tile, int lod,
                                                std::size_t* bytesRead) const {
  auto it = entries_.find(tile);
  if (it == entries_.end()) return nullptr;
  return std::make_shared<const Tile>(
      readTileLod(dir_, *it->second, manifest_.spec, lod, bytesRead));
}

}  // namespace sdfstream
