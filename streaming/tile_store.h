// Where streamed tiles come from: a world pack on disk in production, an in-memory or
// fault-injecting store in tests. The loader calls load() from its worker threads only.
#pragma once

#include <memory>

#include <glm/glm.hpp>

#include "world/partition.h"

namespace sdfstream {

class TileStore {
 public:
  virtual ~TileStore() = default;
  virtual const PartitionSpec& spec() const = 0;
  // True when the pack holds this tile (a cheap manifest lookup; thread-safe). Tiles it does not
  // hold have no surface at any LOD.
  virtual bool hasTile(glm::ivec3 tile) const = 0;
  // Reads, verifies and decodes one LOD of one tile (the returned Tile's lods[lod] is filled;
  // other LODs may be empty): a cascade needs only its own LOD. Blocking I/O; thread-safe.
  // Throws on failure (InputError for corrupt data, std::exception for I/O); the loader retries.
  // *bytesRead receives the bytes this load read from storage (for metrics).
  virtual std::shared_ptr<const Tile> load(glm::ivec3 tile, int lod,
                                           std::size_t* bytesRead) const = 0;
};

}  // namespace sdfstream
