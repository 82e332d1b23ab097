// World pack reading, writing, verification and merging (pack.h); byte layouts in pack_format.h.
#include <algorithm>
#include <array>
#include <atomic>
#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <mutex>
#include <set>
#include <stdexcept>

#include <tbb/parallel_for.h>

#include "core/atomic_dir.h"
#include "core/error.h"
#include "core/hash.h"
#include "world/pack.h"
#include "world/pack_format.h"

namespace fs = std::filesystem;

namespace sdfstream {
namespace {

using namespace pack_format;

// Test hook for "disk full": with SDFSTREAM_FAIL_WRITE_AFTER_BYTES=N in the environment, a pack
// write fails (as a full disk would: the file is cut short, then InputError(Io)) once more than N
// bytes have been written by one PackWriter or mergePacks call.
class WriteBudget {
 public:
  WriteBudget() {
    if (const char* env = std::getenv("SDFSTREAM_FAIL_WRITE_AFTER_BYTES")) {
      char* end = nullptr;
      const long long n = std::strtoll(env, &end, 10);
      if (end != env && *end == '\0' && n >= 0) left_ = n;
    }
  }
  // How many of `size` bytes may be written; fewer than size means the disk is "full".
  std::size_t take(std::size_t size) {
    if (left_.load() < 0) return size;
    const std::int64_t before = left_.fetch_sub(std::int64_t(size));
    return before <= 0 ? 0 : std::min<std::size_t>(size, std::size_t(before));
  }

 private:
  std::atomic<std::int64_t> left_{-1};
};

// Writes `path` inside a staging directory through "<path>.part" + rename, so a file under its
// final name is always complete. Throws InputError(Io) naming the final path.
void writeStagedFile(const fs::path& path, const std::vector<std::uint8_t>& data,
                     WriteBudget& budget) {
  const fs::path part = path.string() + ".part";
  const std::size_t allowed = budget.take(data.size());
  {
    std::ofstream out(part, std::ios::binary | std::ios::trunc);
    if (!out) throw InputError(InputErrorKind::Io, path.string(), "cannot open for writing");
    out.write(reinterpret_cast<const char*>(data.data()), std::streamsize(allowed));
    out.flush();
    if (!out || allowed != data.size()) {
      out.close();
      std::error_code ec;
      fs::remove(part, ec);
      throw InputError(InputErrorKind::Io, path.string(), "write failed (disk full?)");
    }
  }
  std::error_code ec;
  fs::rename(part, path, ec);
  if (ec) throw InputError(InputErrorKind::Io, path.string(), "cannot rename: " + ec.message());
}

std::vector<std::uint8_t> readWholeFile(const fs::path& path) {
  std::ifstream in(path, std::ios::binary | std::ios::ate);
  if (!in) throw InputError(InputErrorKind::Io, path.string(), "cannot open");
  const std::streamoff size = in.tellg();
  if (size < 0) throw InputError(InputErrorKind::Io, path.string(), "cannot read size");
  std::vector<std::uint8_t> data(static_cast<std::size_t>(size));
  in.seekg(0);
  in.read(reinterpret_cast<char*>(data.data()), size);
  if (!in) throw InputError(InputErrorKind::Io, path.string(), "read failed");
  return data;
}

bool sameSpec(const PartitionSpec& a, const PartitionSpec& b) {
  return a.voxelSize == b.voxelSize && a.lodCount == b.lodCount && a.tileVoxels == b.tileVoxels &&
         a.origin == b.origin;
}

// The tile file's size, which must be what the manifest declares (Io, Truncated or Malformed).
std::uintmax_t checkedTileSize(const fs::path& path, const TileEntry& entry) {
  std::error_code ec;
  const std::uintmax_t size = fs::file_size(path, ec);
  if (ec) throw InputError(InputErrorKind::Io, path.string(), "cannot open: " + ec.message());
  if (size != entry.bytes)
    throw InputError(size < entry.bytes ? InputErrorKind::Truncated : InputErrorKind::Malformed,
                     path.string(),
                     std::to_string(size) + " bytes, manifest declares " +
                         std::to_string(entry.bytes));
  return size;
}

// Reads one tile file, checks it against its manifest entry and decodes it; returns the bytes.
// Without a spec, the tile edge comes from the tile itself (specOfTile).
std::vector<std::uint8_t> readVerifiedTile(const fs::path& dir, const TileEntry& entry,
                                           const PartitionSpec* knownSpec, int lodCount,
                                           Tile& tile) {
  const fs::path path = dir / entry.file;
  const std::string file = path.string();
  checkedTileSize(path, entry);
  std::vector<std::uint8_t> bytes = readWholeFile(path);
  if (bytes.size() != entry.bytes)
    throw InputError(InputErrorKind::Truncated, file, "changed size while being read");
  const PartitionSpec spec = knownSpec ? *knownSpec : specOfTile(bytes, lodCount, file);
  tile = decodeTile(bytes, spec, file);
  if (tile.coord != entry.coord)
    throw InputError(InputErrorKind::Malformed, file, "header coordinate differs from its name");
  if (entry.bricksPerLod.size() != std::size_t(spec.lodCount))
    throw InputError(InputErrorKind::Malformed, file, "manifest entry has the wrong LOD count");
  for (int l = 0; l < spec.lodCount; ++l)
    if (tile.lods[l].bricks.size() != entry.bricksPerLod[l])
      throw InputError(InputErrorKind::Malformed, file,
                       "lod" + std::to_string(l) + " brick count differs from the manifest");
  if (checksum64(bytes.data(), bytes.size()) != entry.checksum)
    throw InputError(InputErrorKind::Checksum, file, "file checksum differs from the manifest");
  return bytes;
}

void sortTiles(std::vector<TileEntry>& tiles) {
  std::sort(tiles.begin(), tiles.end(), [](const TileEntry& a, const TileEntry& b) {
    return brickCoordLess(a.coord, b.coord);
  });
}

}  // namespace

struct PackWriter::Impl {
  Impl(const fs::path& d, const PartitionSpec& s) : dir(d), spec(s), out(d) {}
  fs::path dir;
  PartitionSpec spec;
  AtomicDirectory out;
  WriteBudget budget;
  std::mutex mutex;
  std::set<std::array<int, 3>> claimed;  // coords of tiles added (or being added)
  std::vector<TileEntry> tiles;
  bool failed = false, committed = false;
};

PackWriter::PackWriter(const fs::path& dir, const PartitionSpec& spec) {
  if (std::string problem = specProblem(spec); !problem.empty())
    throw InputError(InputErrorKind::Usage, dir.string(), "invalid partition: " + problem);
  impl_ = std::make_unique<Impl>(dir, spec);
  std::error_code ec;
  fs::create_directory(impl_->out.staging() / "tiles", ec);
  if (ec)
    throw InputError(InputErrorKind::Io, dir.string(), "cannot create tiles/: " + ec.message());
}

PackWriter::~PackWriter() = default;

void PackWriter::addTile(const Tile& tile) {
  TileEntry entry;
  entry.coord = tile.coord;
  entry.file = tileFileName(tile.coord);
  std::uint64_t total = 0;
  for (const TileLod& lod : tile.lods) {
    entry.bricksPerLod.push_back(std::uint32_t(lod.bricks.size()));
    total += lod.bricks.size();
  }
  if (total == 0) return;
  if (!coordInRange(tile.coord, impl_->spec))
    throw std::invalid_argument("PackWriter::addTile: tile coordinate out of range");
  {
    std::lock_guard lock(impl_->mutex);
    if (impl_->committed) throw std::logic_error("PackWriter::addTile after commit");
    if (!impl_->claimed.insert({tile.coord.x, tile.coord.y, tile.coord.z}).second)
      throw std::invalid_argument("PackWriter::addTile: " + entry.file + " added twice");
  }
  try {
    const std::vector<std::uint8_t> bytes = encodeTile(tile, impl_->spec);
    entry.bytes = bytes.size();
    entry.checksum = checksum64(bytes.data(), bytes.size());
    writeStagedFile(impl_->out.staging() / entry.file, bytes, impl_->budget);
  } catch (...) {
    std::lock_guard lock(impl_->mutex);
    impl_->failed = true;
    throw;
  }
  std::lock_guard lock(impl_->mutex);
  impl_->tiles.push_back(std::move(entry));
}

void PackWriter::commit(glm::dvec3 boundsMin, glm::dvec3 boundsMax, const std::string& source,
                        const std::vector<std::string>& materials,
                        const std::vector<SceneLight>& lights) {
  std::lock_guard lock(impl_->mutex);
  if (impl_->committed) throw std::logic_error("PackWriter::commit called twice");
  if (impl_->failed)
    throw InputError(InputErrorKind::Io, impl_->dir.string(), "a tile could not be written");
  PackManifest m;
  m.spec = impl_->spec;
  m.boundsMin = boundsMin;
  m.boundsMax = boundsMax;
  m.source = source;
  m.materials = materials;
  m.lights = lights;
  m.tiles = impl_->tiles;
  sortTiles(m.tiles);
  const std::string text = manifestText(m);
  writeStagedFile(impl_->out.staging() / kManifestFile, {text.begin(), text.end()}, impl_->budget);
  impl_->out.commit();
  impl_->committed = true;
}

PackManifest readManifest(const fs::path& dir) {
  const fs::path path = dir / kManifestFile;
  if (!fs::exists(path))
    throw InputError(InputErrorKind::Io, path.string(),
                     fs::exists(dir) ? "missing (not a world pack)" : "no such world");
  const std::vector<std::uint8_t> bytes = readWholeFile(path);
  return parseManifest(std::string(bytes.begin(), bytes.end()), path.string());
}

Tile readTile(const fs::path& dir, const TileEntry& entry, const PartitionSpec& spec) {
  Tile tile;
  readVerifiedTile(dir, entry, &spec, spec.lodCount, tile);
  return tile;
}

Tile readTileLod(const fs::path& dir, const TileEntry& entry, const PartitionSpec& spec, int lod,
                 std::size_t* bytesRead) {
  if (lod < 0 || lod >= spec.lodCount) throw std::invalid_argument("readTileLod: lod out of range");
  const fs::path path = dir / entry.file;
  const std::string file = path.string();
  const std::uintmax_t size = checkedTileSize(path, entry);
  // The buffer has the file's size so every offset check sees the real layout, but only the
  // header and the wanted section are read; the rest stays zero and is never looked at
  // (decodeTile verifies and decodes the masked section only).
  std::vector<std::uint8_t> bytes(static_cast<std::size_t>(size), 0);
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(InputErrorKind::Io, file, "cannot open");
  auto readRange = [&](std::size_t offset, std::size_t count) {
    in.seekg(std::streamoff(offset));
    in.read(reinterpret_cast<char*>(bytes.data() + offset), std::streamsize(count));
    if (!in) throw InputError(InputErrorKind::Truncated, file, "read failed");
  };
  const std::size_t headerBytes =
      std::min<std::size_t>(bytes.size(), pack_format::tileHeaderBytes(spec.lodCount));
  readRange(0, headerBytes);
  const pack_format::TileHeader header = pack_format::decodeTileHeader(bytes, spec, file);
  const auto& section = header.sections[std::size_t(lod)];
  readRange(std::size_t(section.offset), std::size_t(section.bytes));
  if (bytesRead) *bytesRead = headerBytes + std::size_t(section.bytes);
  Tile tile = pack_format::decodeTile(bytes, spec, file, 1u << lod);
  if (tile.coord != entry.coord)
    throw InputError(InputErrorKind::Malformed, file, "header coordinate differs from its name");
  if (entry.bricksPerLod.size() != std::size_t(spec.lodCount) ||
      tile.lods[lod].bricks.size() != entry.bricksPerLod[lod])
    throw InputError(InputErrorKind::Malformed, file,
                     "lod" + std::to_string(lod) + " brick count differs from the manifest");
  return tile;
}

Tile readTile(const fs::path& dir, const TileEntry& entry, int lodCount) {
  if (lodCount < 1 || lodCount > PartitionSpec::kMaxLods)
    throw std::invalid_argument("readTile: lodCount out of range");
  Tile tile;
  readVerifiedTile(dir, entry, nullptr, lodCount, tile);
  return tile;
}

std::string verifyPack(const fs::path& dir) {
  PackManifest m;
  try {
    m = readManifest(dir);
  } catch (const InputError& e) {
    return e.what();
  }
  // Tiles are checked in parallel; the report names the first bad one in manifest order.
  std::vector<std::string> problems(m.tiles.size());
  tbb::parallel_for(std::size_t(0), m.tiles.size(), [&](std::size_t i) {
    try {
      Tile tile;
      readVerifiedTile(dir, m.tiles[i], &m.spec, m.spec.lodCount, tile);
    } catch (const InputError& e) {
      const std::string what = e.what(), prefix = e.file() + ": ";
      problems[i] =
          m.tiles[i].file + ": " + (what.rfind(prefix, 0) == 0 ? what.substr(prefix.size()) : what);
    }
  });
  for (const std::string& p : problems)
    if (!p.empty()) return p;
  return {};
}

World loadLod(const fs::path& dir, int lod) {
  const PackManifest m = readManifest(dir);
  if (lod < 0 || lod >= m.spec.lodCount)
    throw InputError(InputErrorKind::OutOfRange, (dir / kManifestFile).string(),
                     "LOD " + std::to_string(lod) + " requested, the pack has " +
                         std::to_string(m.spec.lodCount));
  std::vector<std::vector<Brick>> perTile(m.tiles.size());
  tbb::parallel_for(std::size_t(0), m.tiles.size(), [&](std::size_t i) {
    Tile tile;
    readVerifiedTile(dir, m.tiles[i], &m.spec, m.spec.lodCount, tile);
    perTile[i] = std::move(tile.lods[lod].bricks);
  });
  World world;
  world.voxelSize = m.spec.lodVoxelSize(lod);
  world.origin = m.spec.origin;
  world.source = m.source;
  std::size_t total = 0;
  for (const auto& bricks : perTile) total += bricks.size();
  world.bricks.reserve(total);
  for (auto& bricks : perTile) {
    world.bricks.insert(world.bricks.end(), std::make_move_iterator(bricks.begin()),
                        std::make_move_iterator(bricks.end()));
    std::vector<Brick>().swap(bricks);
  }
  // Tiles are disjoint and each is sorted, so the coords are unique; only the order across
  // tiles (a tile row interleaves with its neighbours' rows) needs fixing.
  std::sort(world.bricks.begin(), world.bricks.end(),
            [](const Brick& a, const Brick& b) { return brickCoordLess(a.coord, b.coord); });
  return world;
}

void mergePacks(const std::vector<fs::path>& shards, const fs::path& out) {
  if (shards.empty()) throw InputError(InputErrorKind::Usage, out.string(), "no shards to merge");
  struct Source {
    TileEntry entry;
    std::size_t shard;
  };
  std::vector<PackManifest> manifests;
  std::vector<Source> sources;
  for (std::size_t s = 0; s < shards.size(); ++s) {
    manifests.push_back(readManifest(shards[s]));
    const PackManifest& m = manifests.back();
    const std::string file = (shards[s] / kManifestFile).string();
    const std::string first = shards[0].string();
    if (!sameSpec(m.spec, manifests[0].spec))
      throw InputError(InputErrorKind::Malformed, file,
                       "key 'partition' differs from the first shard " + first);
    if (m.source != manifests[0].source)
      throw InputError(InputErrorKind::Malformed, file,
                       "key 'source' differs from the first shard " + first);
    if (m.materials != manifests[0].materials)
      throw InputError(InputErrorKind::Malformed, file,
                       "key 'materials' differs from the first shard " + first);
    for (const TileEntry& e : m.tiles) sources.push_back({e, s});
  }
  std::sort(sources.begin(), sources.end(), [](const Source& a, const Source& b) {
    return brickCoordLess(a.entry.coord, b.entry.coord);
  });
  for (std::size_t i = 1; i < sources.size(); ++i)
    if (sources[i].entry.coord == sources[i - 1].entry.coord)
      throw InputError(InputErrorKind::Malformed, sources[i].entry.file,
                       "tile is in both " + shards[sources[i - 1].shard].string() + " and " +
                           shards[sources[i].shard].string());

  PackManifest merged;
  merged.spec = manifests[0].spec;
  merged.source = manifests[0].source;
  merged.materials = manifests[0].materials;
  merged.lights = manifests[0].lights;  // every shard imports the same sources
  // Shards of one import carry the same (whole-world) bounds; the union keeps that value.
  merged.boundsMin = manifests[0].boundsMin;
  merged.boundsMax = manifests[0].boundsMax;
  for (const PackManifest& m : manifests) {
    merged.boundsMin = glm::min(merged.boundsMin, m.boundsMin);
    merged.boundsMax = glm::max(merged.boundsMax, m.boundsMax);
  }
  for (const Source& s : sources) merged.tiles.push_back(s.entry);

  AtomicDirectory staging(out);
  std::error_code ec;
  fs::create_directory(staging.staging() / "tiles", ec);
  if (ec)
    throw InputError(InputErrorKind::Io, out.string(), "cannot create tiles/: " + ec.message());
  WriteBudget budget;
  tbb::parallel_for(std::size_t(0), sources.size(), [&](std::size_t i) {
    Tile tile;
    const std::vector<std::uint8_t> bytes = readVerifiedTile(
        shards[sources[i].shard], sources[i].entry, &merged.spec, merged.spec.lodCount, tile);
    writeStagedFile(staging.staging() / sources[i].entry.file, bytes, budget);
  });
  const std::string text = manifestText(merged);
  writeStagedFile(staging.staging() / kManifestFile, {text.begin(), text.end()}, budget);
  staging.commit();
}

}  // namespace sdfstream
