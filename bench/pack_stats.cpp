#include "bench/pack_stats.h"

#include "world/pack.h"

namespace fs = std::filesystem;

namespace sdfstream::bench {
namespace {

std::uint64_t directoryBytes(const fs::path& p) {
  if (fs::is_regular_file(p)) return fs::file_size(p);
  std::uint64_t total = 0;
  for (const auto& e : fs::recursive_directory_iterator(p))
    if (e.is_regular_file()) total += e.file_size();
  return total;
}

}  // namespace

PackStats packStats(const fs::path& dir) {
  const PackManifest m = readManifest(dir);
  PackStats s;
  s.tiles = m.tiles.size();
  s.bricksPerLod.assign(std::size_t(m.spec.lodCount), 0);
  for (const TileEntry& t : m.tiles)
    for (std::size_t l = 0; l < t.bricksPerLod.size() && l < s.bricksPerLod.size(); ++l)
      s.bricksPerLod[l] += t.bricksPerLod[l];
  s.bytes = directoryBytes(dir);
  return s;
}

}  // namespace sdfstream::bench
