// The one-voxel-size World on disk, as a world pack (pack.h) with a single LOD. Kept for the
// callers that still work with whole Worlds (import, demo, render) until they build tiles and
// stream them; the bytes are pack files, the old bricks.bin format is gone.
#pragma once

#include <filesystem>

#include "world/world.h"

namespace sdfstream {

// Tile edge used by writeWorld, in voxels: 16 bricks, so a tile's emptyDistance is 4 KiB.
inline constexpr int kWorldTileVoxels = 128;

// Writes `world` as a 1-LOD pack (v0 = world.voxelSize, origin = world.origin, tiles of
// kWorldTileVoxels), atomically (see PackWriter): on failure dir is untouched and no staging
// directory is left. emptyDistance follows partition.h's rule over the World's own bricks
// (slots beyond the one-brick ring count as occupied). Bounds in the manifest are the bricks'
// cell bounds. The World's bricks must be sorted and unique (World's invariant). Deterministic.
// Throws InputError(Io).
void writeWorld(const World& world, const std::filesystem::path& dir);

// loadLod(dir, 0): reads and fully verifies a pack; safe on untrusted input (pack.h's errors).
World readWorld(const std::filesystem::path& dir);

}  // namespace sdfstream
