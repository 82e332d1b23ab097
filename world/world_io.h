// The on-disk world: a directory with world.json (description) and bricks.bin (brick data).
//
// bricks.bin, little-endian (byte offsets):
//   0   char[8]  magic "SDFBRICK"
//   8   u32      version (kBricksVersion)
//   12  u32      section count (4)
//   16  u64      brick count n
//   24  4 × { u64 offset, u64 size, u64 xxh3 checksum }  sections in order:
//         coords    n × 3 × i32          brick coordinates, sorted by brickCoordLess
//         distances n × 729 × u16 (fp16) Brick::distance
//         albedo    n × 512 × u32        Brick::albedo (RGBA8 sRGB)
//         emission  n × 512 × u32        Brick::emission (RGB9E5)
//   120 section data, each section at its offset (8-byte aligned, contiguous, in order).
// world.json: format "sdfstream-world", version, voxelSize, origin, indexMin/indexMax, brickCount,
// source, and bricks.bin's byte size and xxh3 checksum (whole file).
#pragma once

#include <cstdint>
#include <filesystem>

#include "world/world.h"

namespace sdfstream {

inline constexpr std::uint32_t kWorldVersion = 1;
inline constexpr std::uint32_t kBricksVersion = 1;

// Writes dir atomically (core/AtomicDirectory): on failure dir is untouched (an existing one is
// kept), and no temp directory is left behind. Identical worlds give byte-identical files (no
// timestamps, fixed JSON formatting). Throws InputError(Io).
void writeWorld(const World& world, const std::filesystem::path& dir);

// Reads and fully verifies a world written by writeWorld. Safe on untrusted input. Errors
// (InputError, naming the file): Io (missing file), Malformed (bad JSON, wrong types, bad magic,
// inconsistent header, unsorted bricks), Version (format or version not supported), Truncated
// (a file or section shorter than declared), Checksum (names the section, or the whole file when
// only the header differs), NonFinite (voxel size / origin).
World readWorld(const std::filesystem::path& dir);

}  // namespace sdfstream
