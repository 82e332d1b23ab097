// What a written world pack holds, for the import benchmarks' tables: tiles, bricks per LOD and
// bytes on disk.
#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <vector>

namespace sdfstream::bench {

struct PackStats {
  std::size_t tiles = 0;
  std::vector<std::uint64_t> bricksPerLod;
  std::uint64_t bytes = 0;  // every file under the pack directory
};

// Reads the pack's manifest (InputError when it is missing or malformed) and sizes its files.
PackStats packStats(const std::filesystem::path& dir);

}  // namespace sdfstream::bench
