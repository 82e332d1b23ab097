// World pack tiles: readTile(dir, entry, lodCount) and readTileLod (world/pack.h) on arbitrary
// tile bytes.
//
// Every byte of a tile is covered by xxh3 checksums (the manifest's whole-file one, the header's,
// one per section), which a mutating fuzzer cannot forge, so nearly every input would stop at the
// first checksum. The harness therefore plays the honest writer: it recomputes the section and
// header checksums where the header locates them, and builds the manifest entry (size, checksum,
// coordinate, brick counts) from the bytes, so what is fuzzed is the parsing behind the checksums.
// The checksum checks themselves are covered by tests/pack (corruption tests).
#include <cstring>
#include <vector>

#include "core/hash.h"
#include "fuzz/fuzz_support.h"
#include "world/pack.h"
#include "world/pack_format.h"

namespace {

using namespace sdfstream;

template <typename T>
T get(const std::vector<std::uint8_t>& b, std::size_t at) {
  T v;
  std::memcpy(&v, b.data() + at, sizeof v);
  return v;
}
template <typename T>
void put(std::vector<std::uint8_t>& b, std::size_t at, T v) {
  std::memcpy(b.data() + at, &v, sizeof v);
}

// The LOD count the header declares, when it is one readTile accepts; else 1 (the header check
// then reports the mismatch).
int declaredLods(const std::vector<std::uint8_t>& b) {
  if (b.size() < 16) return 1;
  const std::uint32_t l = get<std::uint32_t>(b, 12);
  return l >= 1 && l <= std::uint32_t(PartitionSpec::kMaxLods) ? int(l) : 1;
}

// Rewrites the section checksums (where a descriptor's range lies in the file) and the header
// checksum, as encodeTile writes them (layout in world/pack_format.h).
void repairChecksums(std::vector<std::uint8_t>& b, int lods) {
  const std::size_t header = pack_format::tileHeaderBytes(lods);
  if (b.size() < header) return;
  for (int l = 0; l < lods; ++l) {
    const std::size_t d = 32 + pack_format::kDescriptorBytes * std::size_t(l);
    const std::uint64_t offset = get<std::uint64_t>(b, d + 16), bytes = get<std::uint64_t>(b, d + 24);
    if (offset <= b.size() && bytes <= b.size() - offset)
      put<std::uint64_t>(b, d + 32, checksum64(b.data() + offset, bytes));
  }
  put<std::uint64_t>(b, header - 8, checksum64(b.data(), header - 8));
}

// The manifest entry a writer would have made for these bytes.
TileEntry entryFor(const std::vector<std::uint8_t>& b, int lods) {
  TileEntry e;
  e.file = "tiles/input.tile";
  e.bytes = b.size();
  e.checksum = checksum64(b.data(), b.size());
  if (b.size() >= 28)
    e.coord = {get<std::int32_t>(b, 16), get<std::int32_t>(b, 20), get<std::int32_t>(b, 24)};
  for (int l = 0; l < lods; ++l) {
    const std::size_t d = 32 + pack_format::kDescriptorBytes * std::size_t(l);
    e.bricksPerLod.push_back(b.size() >= d + 4 ? get<std::uint32_t>(b, d) : 0u);
  }
  return e;
}

// What readTile promises (pack.h): lodCount LODs, emptyDistance n³ with n halving per LOD,
// bricks sorted and inside the tile, emptyDistance 0 exactly at brick slots.
void checkTile(const Tile& tile, int lods, std::uint32_t lodMask) {
  fuzz::contract(tile.lods.size() == std::size_t(lods), "one TileLod per LOD");
  for (int l = 0; l < lods; ++l) {
    if (!(lodMask >> l & 1u)) continue;
    const TileLod& lod = tile.lods[std::size_t(l)];
    const std::size_t cells = lod.emptyDistance.size();
    std::size_t n = 1;
    while (n * n * n < cells) ++n;
    fuzz::contract(n * n * n == cells && n >= 1, "emptyDistance is n³");
    const glm::ivec3 base = tile.coord * int(n);
    for (std::size_t i = 0; i < lod.bricks.size(); ++i) {
      const glm::ivec3 local = lod.bricks[i].coord - base;
      fuzz::contract(glm::all(glm::greaterThanEqual(local, glm::ivec3(0))) &&
                         glm::all(glm::lessThan(local, glm::ivec3(int(n)))),
                     "brick inside its tile");
      fuzz::contract(i == 0 || brickCoordLess(lod.bricks[i - 1].coord, lod.bricks[i].coord),
                     "bricks sorted and unique");
      const std::size_t slot = std::size_t(local.x) + n * (std::size_t(local.y) + n * local.z);
      fuzz::contract(lod.emptyDistance[slot] == 0, "emptyDistance 0 at a brick slot");
    }
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  std::vector<std::uint8_t> bytes(data, data + size);
  const int lods = declaredLods(bytes);
  repairChecksums(bytes, lods);
  const TileEntry entry = entryFor(bytes, lods);
  const auto path = fuzz::writeFile(std::filesystem::path("tile") / entry.file, bytes.data(),
                                    bytes.size());
  const std::filesystem::path dir = path.parent_path().parent_path();
  fuzz::expectOnlyInputError([&] { checkTile(readTile(dir, entry, lods), lods, ~0u); });
  // Streaming reads one LOD at a time with the manifest's spec; the spec a tile describes stands
  // in for the manifest here (the LOD from the last byte, so both paths see the same input).
  fuzz::expectOnlyInputError([&] {
    const PartitionSpec spec = pack_format::specOfTile(bytes, lods, path.string());
    const int lod = size > 0 ? int(data[size - 1] % std::uint8_t(lods)) : 0;
    checkTile(readTileLod(dir, entry, spec, lod), lods, 1u << lod);
  });
  return 0;
}
