// Byte-level encoding of world pack files (pack.h): tile files and manifest.json. Internal to
// world/; callers use pack.h.
//
// Tile file tiles/<x>_<y>_<z>.tile, little-endian, byte offsets (L = lodCount):
//   0        char[8]   magic "SDFTILE1"
//   8        u32       version (kTileVersion)
//   12       u32       lodCount L, 1..PartitionSpec::kMaxLods; must equal the manifest's
//   16       i32[3]    tile coordinate
//   28       u32       reserved, 0
//   32       L × 40    section descriptor per LOD l:
//              +0  u32  brickCount n_b (<= n³, n = spec.tileBricks(l))
//              +4  u32  reserved, 0
//              +8  u64  uncompressed bytes, must equal kSectionBytes(n_b, n) below
//              +16 u64  offset of the compressed section in the file
//              +24 u64  compressed bytes
//              +32 u64  xxh3 of the compressed bytes
//   32+40L   u64       xxh3 of bytes [0, 32+40L) (header checksum)
//   40+40L   sections, contiguous in LOD order (offset of LOD 0 = 40+40L), file ends after the
//   last.
// A section is one zstd frame (content size recorded) of, in order:
//   slots     n_b × u32          local slot x + n·(y + n·z) of each brick, strictly increasing
//                                (so bricks are sorted (z,y,x), unique and inside the tile)
//   distances n_b × 729 × u16    Brick::distance (fp16)
//   albedo    n_b × 512 × u32    Brick::albedo (RGBA8 sRGB)
//   emission  n_b × 512 × u32    Brick::emission (RGB9E5)
//   empty     n³ × u8            TileLod::emptyDistance (0 exactly where a brick is stored)
// The manifest keeps the whole file's size and xxh3, so every byte is covered twice.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "world/pack.h"

namespace sdfstream::pack_format {

inline constexpr char kTileMagic[8] = {'S', 'D', 'F', 'T', 'I', 'L', 'E', '1'};
inline constexpr std::uint32_t kTileVersion = 1;
inline constexpr std::uint32_t kManifestVersion = 1;
inline constexpr const char* kManifestFormat = "sdfstream-pack";
inline constexpr const char* kManifestFile = "manifest.json";
inline constexpr std::size_t kDescriptorBytes = 40;
inline constexpr std::uint64_t kBrickPayloadBytes =
    4 + layout::kBrickSampleCount * 2 + layout::kBrickMaterialCount * 4 * 2;
// Limits that keep a hostile file from making the reader allocate without bound: a tile edge of
// at most 1024 LOD-0 bricks, and at most 8 GiB per uncompressed section (also bounded by zstd's
// largest possible ratio times the compressed size, see decodeTile).
inline constexpr int kMaxTileBricks = 1024;
inline constexpr std::uint64_t kMaxSectionBytes = 8ull << 30;
// The manifest's optional "lights" list: at most as many as a glTF import may place.
inline constexpr std::size_t kMaxManifestLights = 1024;

constexpr std::size_t tileHeaderBytes(int lodCount) { return 40 + kDescriptorBytes * lodCount; }
constexpr std::uint64_t sectionBytes(std::uint64_t bricks, std::uint64_t n) {
  return bricks * kBrickPayloadBytes + n * n * n;
}

// "tiles/<x>_<y>_<z>.tile", the only name a tile with that coordinate may have.
std::string tileFileName(glm::ivec3 coord);

// Empty when the spec follows partition.h's rules and this format's limits, else the problem.
std::string specProblem(const PartitionSpec& spec);

// Whether a tile coordinate keeps every voxel index of the tile (and its neighbours) in int32.
bool coordInRange(glm::ivec3 coord, const PartitionSpec& spec);

// Encodes a tile (bricks sorted, inside the tile, emptyDistance n³ per LOD: checked, throws
// std::invalid_argument otherwise, a programming error). Deterministic.
std::vector<std::uint8_t> encodeTile(const Tile& tile, const PartitionSpec& spec);

// What the header of a tile says, after checking magic, version, layout and header checksum.
struct TileHeader {
  glm::ivec3 coord{0};
  struct Section {
    std::uint32_t bricks = 0;
    std::uint64_t rawBytes = 0, offset = 0, bytes = 0, checksum = 0;
  };
  std::vector<Section> sections;
};
// Safe on untrusted bytes; errors are InputError naming `file`.
TileHeader decodeTileHeader(const std::vector<std::uint8_t>& bytes, const PartitionSpec& spec,
                            const std::string& file);
// The tile edge a tile file declares (n³ emptyDistance bytes in its LOD-0 section), as a spec
// with that tileVoxels and lodCount, voxelSize 1 and origin 0. Safe on untrusted bytes.
PartitionSpec specOfTile(const std::vector<std::uint8_t>& bytes, int lodCount,
                         const std::string& file);
// Full decode and verification (header, section checksums, zstd sizes, slots, emptyDistance).
// With a lodMask, only the LODs whose bit is set are verified and decoded (the others stay
// empty): streaming decodes the one LOD a cascade needs.
Tile decodeTile(const std::vector<std::uint8_t>& bytes, const PartitionSpec& spec,
                const std::string& file, std::uint32_t lodMask = ~0u);

// manifest.json text: fixed key order, 2-space indent, trailing newline, no timestamps.
std::string manifestText(const PackManifest& manifest);
// Safe on untrusted text; InputError(Malformed) names the key, (Version) for other formats.
PackManifest parseManifest(const std::string& text, const std::string& file);

}  // namespace sdfstream::pack_format
