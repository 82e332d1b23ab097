#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <string>

#include "core/atomic_dir.h"
#include "core/error.h"
#include "tools/args.h"
#include "tools/commands.h"
#include "world/pack.h"
#include "world/pack_import.h"

namespace sdfstream::cli {
namespace {

std::string clock(double seconds) {
  const long s = long(seconds + 0.5);
  char buf[32];
  if (s >= 3600)
    std::snprintf(buf, sizeof buf, "%ld:%02ld:%02ld", s / 3600, s / 60 % 60, s % 60);
  else
    std::snprintf(buf, sizeof buf, "%ld:%02ld", s / 60, s % 60);
  return buf;
}

// Progress on stderr: a redrawn bar with ETA on a terminal, else a line every ~10%.
class Progress {
 public:
  Progress() : tty_(::isatty(STDERR_FILENO) != 0), start_(std::chrono::steady_clock::now()) {}

  void operator()(std::size_t done, std::size_t total) {
    const double elapsed = seconds();
    const double eta = done ? elapsed / double(done) * double(total - done) : 0.0;
    if (tty_) {
      constexpr int kWidth = 30;
      const int filled = total ? int(kWidth * done / total) : kWidth;
      std::fprintf(stderr, "\r[%s%s] %zu/%zu tiles  %s elapsed  ETA %s ",
                   std::string(std::size_t(filled), '#').c_str(),
                   std::string(std::size_t(kWidth - filled), '.').c_str(), done, total,
                   clock(elapsed).c_str(), clock(eta).c_str());
      if (done == total) std::fputc('\n', stderr);
    } else {
      const std::size_t decile = total ? done * 10 / total : 10;
      if (decile > lastDecile_ || done == total) {
        lastDecile_ = decile;
        std::fprintf(stderr, "import: %zu/%zu tiles, %s elapsed, ETA %s\n", done, total,
                     clock(elapsed).c_str(), clock(eta).c_str());
      }
    }
    std::fflush(stderr);
  }

  double seconds() const {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  }

 private:
  bool tty_;
  std::chrono::steady_clock::time_point start_;
  std::size_t lastDecile_ = 0;
};

}  // namespace

int runImport(int argc, char** argv) {
  Args args(argc, argv, 2,
            {"-o", "--voxel", "--lods", "--tile-voxels", "--shard", "--max-memory-gib"},
            {"--help", "-h"});
  if (args.has("--help") || args.has("-h")) {
    std::puts(
        "usage: sdfstream import INPUT -o WORLD [--voxel SIZE] [--lods N] [--tile-voxels N]\n"
        "                        [--shard i/n] [--max-memory-gib N]\n"
        "\n"
        "Builds a world pack: tiles of 8^3 SDF bricks at LOD 0..N-1 (LOD l has voxel SIZE*2^l).\n"
        "INPUT is a glTF 2.0 scene (.gltf/.glb), an OpenVDB level set (.vdb), an OBJ mesh, or a\n"
        "layout (.json) placing several of them. WORLD is written atomically: a failed import\n"
        "leaves no directory behind and an existing WORLD untouched. Tiles are built in\n"
        "parallel; progress and ETA go to stderr.\n"
        "\n"
        "  --voxel SIZE         LOD-0 voxel edge in metres (default: the .vdb grid's own; for\n"
        "                       meshes the largest scene extent / 112)\n"
        "  --lods N             number of LODs, 1..8 (default 4)\n"
        "  --tile-voxels N      tile edge in LOD-0 voxels, a multiple of 8*2^(N-1) (default 128)\n"
        "  --shard i/n          build only the tiles whose rank (sorted z,y,x) mod n is i, for\n"
        "                       imports split over machines; join with 'sdfstream merge'\n"
        "  --max-memory-gib N   refuse voxel sizes whose estimated level sets exceed N GiB (8)");
    return 0;
  }
  if (args.positional().size() != 1 || !args.value("-o"))
    throw InputError(InputErrorKind::Usage, "command line",
                     "expected: sdfstream import INPUT -o WORLD (see --help)");
  // First of all: an import killed earlier may have left its staging, or (killed inside the
  // commit) the previous world only as its backup. Put that right even if this run then fails.
  recoverInterruptedOutput(*args.value("-o"));
  PackImportOptions options;
  options.voxelSize = args.number("--voxel", 0.0);
  if (options.voxelSize < 0.0)
    throw InputError(InputErrorKind::Usage, "command line", "--voxel must be positive");
  options.lodCount = args.integer("--lods", 4, 1, PartitionSpec::kMaxLods);
  options.tileVoxels = args.integer("--tile-voxels", 128, 8, 1 << 16);
  const double gibs = args.number("--max-memory-gib", 8.0);
  if (!(gibs > 0.0))
    throw InputError(InputErrorKind::Usage, "command line", "--max-memory-gib must be positive");
  options.limits.maxBytes = std::size_t(gibs * double(1ull << 30));
  if (auto shard = args.value("--shard")) {
    int i = -1, n = 0;
    char tail = 0;
    if (std::sscanf(shard->c_str(), "%d/%d%c", &i, &n, &tail) != 2 || n < 1 || i < 0 || i >= n)
      throw InputError(InputErrorKind::Usage, "command line",
                       "--shard expects i/n with 0 <= i < n, got '" + *shard + "'");
    options.shardIndex = i;
    options.shardCount = n;
  }

  const std::string input = args.positional()[0];
  const std::string name = std::filesystem::path(input).filename().string();
  Progress progress;
  options.progress = [&progress](std::size_t done, std::size_t total) { progress(done, total); };
  auto sources = sourcesForInput(input, options.voxelSize, options.limits);
  const PartitionSpec spec = partitionFor(sources, options, name);
  importPack(sources, *args.value("-o"), spec, options, name);
  const double seconds = progress.seconds();

  const PackManifest manifest = readManifest(*args.value("-o"));
  std::size_t bricks = 0;
  for (const TileEntry& t : manifest.tiles)
    for (std::uint32_t n : t.bricksPerLod) bricks += n;
  std::printf(
      "imported %s: %zu tiles, %zu bricks over %d LODs, voxel %.4g m, tile %.4g m, "
      "bounds (%.3f %.3f %.3f)..(%.3f %.3f %.3f), %.2f s (%.0f bricks/s)\n",
      input.c_str(), manifest.tiles.size(), bricks, spec.lodCount, spec.voxelSize,
      spec.tileSizeMeters(), manifest.boundsMin.x, manifest.boundsMin.y, manifest.boundsMin.z,
      manifest.boundsMax.x, manifest.boundsMax.y, manifest.boundsMax.z, seconds,
      seconds > 0 ? double(bricks) / seconds : 0.0);
  return 0;
}

}  // namespace sdfstream::cli
