// sdfstream info / verify / merge: world pack inspection and shard merging (world/pack.h).
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "core/error.h"
#include "tools/args.h"
#include "tools/commands.h"
#include "world/pack.h"
#include "world/pack_format.h"

namespace sdfstream::cli {

int runInfo(int argc, char** argv) {
  Args args(argc, argv, 2, {}, {"--help", "-h"});
  if (args.has("--help") || args.has("-h")) {
    std::puts(
        "usage: sdfstream info WORLD\n"
        "\n"
        "Prints a world pack's summary (format, partition, bounds, tiles, bricks per LOD, bytes\n"
        "and compression ratio) after verifying every checksum; exits 1 if one fails.");
    return 0;
  }
  if (args.positional().size() != 1)
    throw InputError(InputErrorKind::Usage, "command line", "expected: sdfstream info WORLD");
  const std::filesystem::path dir = args.positional()[0];
  const PackManifest m = readManifest(dir);
  std::vector<std::uint64_t> bricks(m.spec.lodCount, 0);
  std::uint64_t diskBytes = std::filesystem::file_size(dir / pack_format::kManifestFile);
  std::uint64_t rawBytes = 0;
  for (const TileEntry& t : m.tiles) {
    diskBytes += t.bytes;
    for (int l = 0; l < m.spec.lodCount; ++l) {
      bricks[l] += t.bricksPerLod[l];
      rawBytes += pack_format::sectionBytes(t.bricksPerLod[l], std::uint64_t(m.spec.tileBricks(l)));
    }
  }
  const std::string problem = verifyPack(dir);
  std::printf(
      "world      %s\nformat     %s version %u (tiles version %u)\nsource     %s\n"
      "voxel      %.6g m (LOD 0), %d LODs up to %.6g m\ntile       %.6g m (%d voxels)\n"
      "origin     (%.3f, %.3f, %.3f) m\n"
      "bounds     (%.3f, %.3f, %.3f) .. (%.3f, %.3f, %.3f) m\ntiles      %zu\n",
      dir.c_str(), pack_format::kManifestFormat, pack_format::kManifestVersion,
      pack_format::kTileVersion, m.source.c_str(), m.spec.voxelSize, m.spec.lodCount,
      m.spec.lodVoxelSize(m.spec.lodCount - 1), m.spec.tileSizeMeters(), m.spec.tileVoxels,
      m.spec.origin.x, m.spec.origin.y, m.spec.origin.z, m.boundsMin.x, m.boundsMin.y,
      m.boundsMin.z, m.boundsMax.x, m.boundsMax.y, m.boundsMax.z, m.tiles.size());
  for (int l = 0; l < m.spec.lodCount; ++l)
    std::printf("bricks     LOD %d: %llu\n", l, static_cast<unsigned long long>(bricks[l]));
  std::printf("bytes      %.2f MiB on disk, %.2f MiB uncompressed, ratio %.2f\n",
              double(diskBytes) / (1 << 20), double(rawBytes) / (1 << 20),
              diskBytes ? double(rawBytes) / double(diskBytes) : 0.0);
  if (!problem.empty()) {
    std::printf("checksums  FAILED\n");
    std::fprintf(stderr, "sdfstream info: %s\n", problem.c_str());
    return 1;
  }
  std::printf("checksums  ok\n");
  return 0;
}

int runVerify(int argc, char** argv) {
  Args args(argc, argv, 2, {}, {"--help", "-h"});
  if (args.has("--help") || args.has("-h")) {
    std::puts(
        "usage: sdfstream verify WORLD\n"
        "\n"
        "Reads the manifest and every tile of a world pack, checking sizes, every section's\n"
        "checksum and each whole file's checksum. Prints \"ok: N tiles verified\" and exits 0,\n"
        "or prints the first problem as one line naming the bad tile and exits 1.");
    return 0;
  }
  if (args.positional().size() != 1)
    throw InputError(InputErrorKind::Usage, "command line", "expected: sdfstream verify WORLD");
  const std::filesystem::path dir = args.positional()[0];
  const std::string problem = verifyPack(dir);
  if (!problem.empty()) {
    std::fprintf(stderr, "sdfstream verify: %s\n", problem.c_str());
    return 1;
  }
  std::printf("ok: %zu tiles verified\n", readManifest(dir).tiles.size());
  return 0;
}

int runMerge(int argc, char** argv) {
  Args args(argc, argv, 2, {"-o"}, {"--help", "-h"});
  if (args.has("--help") || args.has("-h")) {
    std::puts(
        "usage: sdfstream merge SHARD... -o WORLD\n"
        "\n"
        "Joins world packs imported with --shard i/n into one pack. The shards must share the\n"
        "partition (voxel size, LODs, tile size, origin), source and materials, and hold disjoint\n"
        "tiles. Every tile is verified and copied byte for byte, so the result is identical to a\n"
        "one-shot import. WORLD is written atomically: on failure an existing WORLD is kept.");
    return 0;
  }
  if (args.positional().empty() || !args.value("-o"))
    throw InputError(InputErrorKind::Usage, "command line",
                     "expected: sdfstream merge SHARD... -o WORLD (see --help)");
  std::vector<std::filesystem::path> shards(args.positional().begin(), args.positional().end());
  mergePacks(shards, *args.value("-o"));
  const PackManifest m = readManifest(*args.value("-o"));
  std::printf("merged %zu shards: %zu tiles into %s\n", shards.size(), m.tiles.size(),
              args.value("-o")->c_str());
  return 0;
}

}  // namespace sdfstream::cli
