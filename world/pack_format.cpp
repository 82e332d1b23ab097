#include "world/pack_format.h"

#include <algorithm>
#include <bit>
#include <climits>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <stdexcept>

#include <zstd.h>

#include "core/error.h"
#include "core/hash.h"

namespace sdfstream::pack_format {
namespace {

static_assert(std::endian::native == std::endian::little, "tile files are little-endian");
static_assert(kBrickPayloadBytes == 4 + 729 * 2 + 512 * 8, "tile section layout (pack_format.h)");

constexpr int kZstdLevel = 3;
// zstd decodes at most 128 KiB per block and a block costs at least 3 bytes, so no frame
// expands by more than this factor (plus one block); used to bound allocations.
constexpr std::uint64_t kZstdMaxRatio = (128 * 1024) / 3 + 1;

template <typename T>
void put(std::vector<std::uint8_t>& out, std::size_t at, T v) {
  std::memcpy(out.data() + at, &v, sizeof v);
}
template <typename T>
T get(const std::vector<std::uint8_t>& in, std::size_t at) {
  T v;
  std::memcpy(&v, in.data() + at, sizeof v);
  return v;
}

[[noreturn]] void fail(InputErrorKind kind, const std::string& file, const std::string& what) {
  throw InputError(kind, file, what);
}

std::string lodName(int lod) { return "lod" + std::to_string(lod); }

std::uint64_t cube(std::uint64_t n) { return n * n * n; }

// Uncompressed section of one LOD, layout in pack_format.h.
std::vector<std::uint8_t> rawSection(const TileLod& lod, glm::ivec3 tile, int n) {
  const std::size_t count = lod.bricks.size();
  std::vector<std::uint8_t> raw(sectionBytes(count, std::uint64_t(n)));
  std::uint8_t* slots = raw.data();
  std::uint8_t* dist = slots + count * 4;
  std::uint8_t* albedo = dist + count * layout::kBrickSampleCount * 2;
  std::uint8_t* emission = albedo + count * layout::kBrickMaterialCount * 4;
  std::uint8_t* empty = emission + count * layout::kBrickMaterialCount * 4;
  const glm::ivec3 base = tile * n;
  std::int64_t previous = -1;
  for (std::size_t i = 0; i < count; ++i) {
    const Brick& b = lod.bricks[i];
    const glm::ivec3 local = b.coord - base;
    if (glm::any(glm::lessThan(local, glm::ivec3(0))) ||
        glm::any(glm::greaterThanEqual(local, glm::ivec3(n))))
      throw std::invalid_argument("encodeTile: brick outside its tile");
    const std::uint32_t slot = std::uint32_t(local.x + n * (local.y + n * local.z));
    if (std::int64_t(slot) <= previous)
      throw std::invalid_argument("encodeTile: bricks not sorted or not unique");
    if (lod.emptyDistance[slot] != 0)
      throw std::invalid_argument("encodeTile: emptyDistance of a brick slot is not 0");
    previous = slot;
    std::memcpy(slots + i * 4, &slot, 4);
    std::memcpy(dist + i * layout::kBrickSampleCount * 2, b.distance.data(),
                layout::kBrickSampleCount * 2);
    std::memcpy(albedo + i * layout::kBrickMaterialCount * 4, b.albedo.data(),
                layout::kBrickMaterialCount * 4);
    std::memcpy(emission + i * layout::kBrickMaterialCount * 4, b.emission.data(),
                layout::kBrickMaterialCount * 4);
  }
  std::memcpy(empty, lod.emptyDistance.data(), lod.emptyDistance.size());
  return raw;
}

}  // namespace

std::string tileFileName(glm::ivec3 c) {
  return "tiles/" + std::to_string(c.x) + "_" + std::to_string(c.y) + "_" + std::to_string(c.z) +
         ".tile";
}

bool coordInRange(glm::ivec3 c, const PartitionSpec& spec) {
  // LOD-0 voxel indices of the tile (and one tile beyond, for rings) must fit in int32.
  const std::int64_t limit = std::int64_t(INT32_MAX) / spec.tileVoxels - 2;
  for (int a = 0; a < 3; ++a)
    if (c[a] < -limit || c[a] > limit) return false;
  return true;
}

std::string specProblem(const PartitionSpec& s) {
  if (!std::isfinite(s.voxelSize) || !(s.voxelSize > 0.0)) return "voxelSize must be finite > 0";
  if (!std::isfinite(s.origin.x) || !std::isfinite(s.origin.y) || !std::isfinite(s.origin.z))
    return "origin must be finite";
  if (s.lodCount < 1 || s.lodCount > PartitionSpec::kMaxLods)
    return "lodCount must be 1.." + std::to_string(PartitionSpec::kMaxLods);
  const int step = 8 << (s.lodCount - 1);
  if (s.tileVoxels <= 0 || s.tileVoxels % step != 0)
    return "tileVoxels must be a positive multiple of " + std::to_string(step);
  if (s.tileVoxels / 8 > kMaxTileBricks)
    return "tileVoxels must be at most " + std::to_string(kMaxTileBricks * 8);
  return {};
}

std::vector<std::uint8_t> encodeTile(const Tile& tile, const PartitionSpec& spec) {
  if (int(tile.lods.size()) != spec.lodCount)
    throw std::invalid_argument("encodeTile: tile has " + std::to_string(tile.lods.size()) +
                                " LODs, spec " + std::to_string(spec.lodCount));
  const std::size_t headerBytes = tileHeaderBytes(spec.lodCount);
  std::vector<std::vector<std::uint8_t>> compressed(tile.lods.size());
  std::vector<std::uint64_t> rawBytes(tile.lods.size());
  std::size_t total = headerBytes;
  for (int l = 0; l < spec.lodCount; ++l) {
    const int n = spec.tileBricks(l);
    if (tile.lods[l].emptyDistance.size() != cube(std::uint64_t(n)))
      throw std::invalid_argument("encodeTile: emptyDistance of " + lodName(l) + " is not n³");
    const std::vector<std::uint8_t> raw = rawSection(tile.lods[l], tile.coord, n);
    rawBytes[l] = raw.size();
    compressed[l].resize(ZSTD_compressBound(raw.size()));
    const std::size_t size = ZSTD_compress(compressed[l].data(), compressed[l].size(), raw.data(),
                                           raw.size(), kZstdLevel);
    if (ZSTD_isError(size))
      throw std::runtime_error(std::string("zstd compression failed: ") + ZSTD_getErrorName(size));
    compressed[l].resize(size);
    total += size;
  }
  std::vector<std::uint8_t> out(total, 0);
  std::memcpy(out.data(), kTileMagic, 8);
  put<std::uint32_t>(out, 8, kTileVersion);
  put<std::uint32_t>(out, 12, std::uint32_t(spec.lodCount));
  put<std::int32_t>(out, 16, tile.coord.x);
  put<std::int32_t>(out, 20, tile.coord.y);
  put<std::int32_t>(out, 24, tile.coord.z);
  std::uint64_t offset = headerBytes;
  for (int l = 0; l < spec.lodCount; ++l) {
    const std::size_t d = 32 + kDescriptorBytes * l;
    put<std::uint32_t>(out, d, std::uint32_t(tile.lods[l].bricks.size()));
    put<std::uint64_t>(out, d + 8, rawBytes[l]);
    put<std::uint64_t>(out, d + 16, offset);
    put<std::uint64_t>(out, d + 24, compressed[l].size());
    put<std::uint64_t>(out, d + 32, checksum64(compressed[l].data(), compressed[l].size()));
    std::memcpy(out.data() + offset, compressed[l].data(), compressed[l].size());
    offset += compressed[l].size();
  }
  put<std::uint64_t>(out, headerBytes - 8, checksum64(out.data(), headerBytes - 8));
  return out;
}

TileHeader decodeTileHeader(const std::vector<std::uint8_t>& bytes, const PartitionSpec& spec,
                            const std::string& file) {
  if (bytes.size() < tileHeaderBytes(1))
    fail(InputErrorKind::Truncated, file, "shorter than a tile header");
  if (std::memcmp(bytes.data(), kTileMagic, 8) != 0)
    fail(InputErrorKind::Malformed, file, "bad magic (not a tile file)");
  const std::uint32_t version = get<std::uint32_t>(bytes, 8);
  if (version != kTileVersion)
    fail(InputErrorKind::Version, file,
         "tile version " + std::to_string(version) + " is not supported (expected " +
             std::to_string(kTileVersion) + ")");
  const std::uint32_t lodCount = get<std::uint32_t>(bytes, 12);
  if (lodCount != std::uint32_t(spec.lodCount))
    fail(InputErrorKind::Malformed, file,
         "header says " + std::to_string(lodCount) + " LODs, manifest " +
             std::to_string(spec.lodCount));
  const std::size_t headerBytes = tileHeaderBytes(spec.lodCount);
  if (bytes.size() < headerBytes) fail(InputErrorKind::Truncated, file, "file ends inside header");
  if (checksum64(bytes.data(), headerBytes - 8) != get<std::uint64_t>(bytes, headerBytes - 8))
    fail(InputErrorKind::Checksum, file, "header checksum mismatch");
  if (get<std::uint32_t>(bytes, 28) != 0) fail(InputErrorKind::Malformed, file, "reserved != 0");

  TileHeader h;
  h.coord = {get<std::int32_t>(bytes, 16), get<std::int32_t>(bytes, 20),
             get<std::int32_t>(bytes, 24)};
  if (!coordInRange(h.coord, spec))
    fail(InputErrorKind::OutOfRange, file, "tile coordinate out of range");
  std::uint64_t expectedOffset = headerBytes;
  for (int l = 0; l < spec.lodCount; ++l) {
    const std::size_t d = 32 + kDescriptorBytes * l;
    TileHeader::Section s;
    s.bricks = get<std::uint32_t>(bytes, d);
    s.rawBytes = get<std::uint64_t>(bytes, d + 8);
    s.offset = get<std::uint64_t>(bytes, d + 16);
    s.bytes = get<std::uint64_t>(bytes, d + 24);
    s.checksum = get<std::uint64_t>(bytes, d + 32);
    const std::uint64_t n = std::uint64_t(spec.tileBricks(l));
    if (get<std::uint32_t>(bytes, d + 4) != 0 || s.bricks > cube(n) ||
        s.rawBytes != sectionBytes(s.bricks, n) || s.offset != expectedOffset)
      fail(InputErrorKind::Malformed, file, "bad descriptor of section " + lodName(l));
    if (s.bytes > bytes.size() - s.offset)
      fail(InputErrorKind::Truncated, file, "file ends inside section " + lodName(l));
    if (s.rawBytes > kMaxSectionBytes || s.rawBytes > (s.bytes + 1) * kZstdMaxRatio)
      fail(InputErrorKind::TooLarge, file, "section " + lodName(l) + " expands beyond the limit");
    expectedOffset += s.bytes;
    h.sections.push_back(s);
  }
  if (expectedOffset != bytes.size())
    fail(InputErrorKind::Malformed, file,
         std::to_string(bytes.size() - expectedOffset) + " bytes after the last section");
  return h;
}

PartitionSpec specOfTile(const std::vector<std::uint8_t>& bytes, int lodCount,
                         const std::string& file) {
  PartitionSpec spec;
  spec.voxelSize = 1.0;
  spec.lodCount = lodCount;
  if (bytes.size() >= tileHeaderBytes(1)) {
    const std::uint64_t bricks = get<std::uint32_t>(bytes, 32), raw = get<std::uint64_t>(bytes, 40);
    const std::uint64_t slots =
        raw >= bricks * kBrickPayloadBytes ? raw - bricks * kBrickPayloadBytes : 0;
    std::uint64_t n = std::uint64_t(std::llround(std::cbrt(double(slots))));
    if (n >= 1 && n <= std::uint64_t(kMaxTileBricks) && cube(n) == slots)
      spec.tileVoxels = int(8 * n);
  }
  // A header too short or inconsistent gets tileVoxels 0; decodeTileHeader then reports the
  // precise problem (truncation, magic, version) before it looks at sizes.
  if (spec.tileVoxels == 0 || !specProblem(spec).empty()) {
    PartitionSpec fallback = spec;
    fallback.tileVoxels = 8 << (std::max(lodCount, 1) - 1);
    decodeTileHeader(bytes, fallback, file);
    fail(InputErrorKind::Malformed, file, "section lod0 does not describe a valid tile edge");
  }
  return spec;
}

Tile decodeTile(const std::vector<std::uint8_t>& bytes, const PartitionSpec& spec,
                const std::string& file, std::uint32_t lodMask) {
  const TileHeader h = decodeTileHeader(bytes, spec, file);
  for (int l = 0; l < spec.lodCount; ++l)
    if ((lodMask >> l & 1u) && checksum64(bytes.data() + h.sections[l].offset, h.sections[l].bytes) !=
        h.sections[l].checksum)
      fail(InputErrorKind::Checksum, file, "section " + lodName(l) + " checksum mismatch");

  Tile tile;
  tile.coord = h.coord;
  tile.lods.resize(spec.lodCount);
  std::vector<std::uint8_t> raw;
  for (int l = 0; l < spec.lodCount; ++l) {
    if (!(lodMask >> l & 1u)) continue;
    const TileHeader::Section& s = h.sections[l];
    const std::uint8_t* src = bytes.data() + s.offset;
    const unsigned long long declared = ZSTD_getFrameContentSize(src, s.bytes);
    if (declared != s.rawBytes)
      fail(InputErrorKind::Malformed, file, "section " + lodName(l) + " is not the declared size");
    raw.resize(s.rawBytes);
    const std::size_t got = ZSTD_decompress(raw.data(), raw.size(), src, s.bytes);
    if (ZSTD_isError(got) || got != s.rawBytes)
      fail(InputErrorKind::Malformed, file, "section " + lodName(l) + " does not decompress");

    const int n = spec.tileBricks(l);
    const std::size_t count = s.bricks;
    const std::uint8_t* slots = raw.data();
    const std::uint8_t* dist = slots + count * 4;
    const std::uint8_t* albedo = dist + count * layout::kBrickSampleCount * 2;
    const std::uint8_t* emission = albedo + count * layout::kBrickMaterialCount * 4;
    const std::uint8_t* empty = emission + count * layout::kBrickMaterialCount * 4;
    TileLod& lod = tile.lods[l];
    lod.emptyDistance.assign(empty, empty + cube(std::uint64_t(n)));
    lod.bricks.resize(count);
    const glm::ivec3 base = tile.coord * n;
    std::int64_t previous = -1;
    for (std::size_t i = 0; i < count; ++i) {
      std::uint32_t slot;
      std::memcpy(&slot, slots + i * 4, 4);
      if (std::int64_t(slot) <= previous || slot >= cube(std::uint64_t(n)))
        fail(InputErrorKind::Malformed, file,
             "section " + lodName(l) + ": brick slots not sorted or outside the tile");
      if (lod.emptyDistance[slot] != 0)
        fail(InputErrorKind::Malformed, file,
             "section " + lodName(l) + ": emptyDistance of a brick slot is not 0");
      previous = slot;
      Brick& b = lod.bricks[i];
      const int x = int(slot % std::uint32_t(n)), y = int(slot / std::uint32_t(n) % n),
                z = int(slot / std::uint32_t(n * n));
      b.coord = base + glm::ivec3(x, y, z);
      std::memcpy(b.distance.data(), dist + i * layout::kBrickSampleCount * 2,
                  layout::kBrickSampleCount * 2);
      std::memcpy(b.albedo.data(), albedo + i * layout::kBrickMaterialCount * 4,
                  layout::kBrickMaterialCount * 4);
      std::memcpy(b.emission.data(), emission + i * layout::kBrickMaterialCount * 4,
                  layout::kBrickMaterialCount * 4);
    }
  }
  return tile;
}

}  // namespace sdfstream::pack_format
