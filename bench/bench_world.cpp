#include <algorithm>
#include <chrono>
#include <cstdio>
#include <fstream>
#include <string>

#include "bench/bench_import.h"
#include "bench/pack_stats.h"
#include "core/stopwatch.h"
#include "world/layout_sources.h"
#include "world/pack.h"
#include "world/pack_import.h"

namespace sdfstream::bench {
namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

}  // namespace

int runWorldBench(const WorldBenchOptions& o) {
  const fs::path& layout = o.layout;
  const fs::path& outDir = o.out;
  PackImportOptions options;
  options.voxelSize = o.voxel;
  options.lodCount = o.lods;
  options.tileVoxels = o.tileVoxels;
  options.limits.maxBytes = o.maxMemoryBytes;
  fs::create_directories(outDir);
  const fs::path pack = outDir / "pack";

  const auto start = Clock::now();
  const auto sources = loadLayoutSources(layout);
  const double tLoad = secondsSince(start);
  const PartitionSpec spec = partitionFor(sources, options, layout.filename().string());
  const auto buildStart = Clock::now();
  options.progress = [&](std::size_t done, std::size_t total) {
    const double t = secondsSince(buildStart);
    const double eta = done ? t / double(done) * double(total - done) : 0.0;
    const int width = 30,
              filled = int(double(width) * double(done) / double(std::max<std::size_t>(total, 1)));
    std::fprintf(stderr, "\r[%s%s] %zu/%zu tiles, %.0f s, ETA %.0f s   ",
                 std::string(std::size_t(filled), '#').c_str(),
                 std::string(std::size_t(width - filled), '.').c_str(), done, total, t, eta);
    if (done == total) std::fputc('\n', stderr);
  };
  importPack(sources, pack, spec, options, layout.filename().string());
  const double tTotal = secondsSince(start);
  const PackStats s = packStats(pack);
  const std::string problem = verifyPack(pack);

  std::uint64_t bricks = 0;
  std::string perLod;
  for (std::size_t l = 0; l < s.bricksPerLod.size(); ++l) {
    bricks += s.bricksPerLod[l];
    perLod += (l ? " / " : "") + std::to_string(s.bricksPerLod[l]);
  }
  char buf[2048];
  std::snprintf(
      buf, sizeof buf,
      "# bench world\n\nlayout `%s`: %zu sources, voxel %.4g m, %d LODs, tiles of %d "
      "voxels (%.0f m)\n\n"
      "| load sources (s) | import (s) | tiles | bricks (LOD 0 / 1 / ...) | MiB | "
      "verify |\n|---|---|---|---|---|---|\n| %.2f | %.1f | %zu | %llu (%s) | %.1f | %s |\n",
      layout.c_str(), sources.size(), spec.voxelSize, spec.lodCount, spec.tileVoxels,
      spec.tileSizeMeters(), tLoad, tTotal, s.tiles, (unsigned long long)bricks, perLod.c_str(),
      double(s.bytes) / double(1 << 20), problem.empty() ? "ok" : problem.c_str());
  std::ofstream(outDir / "summary.md") << buf;
  std::ofstream csv(outDir / "results.csv");
  csv << "layout,sources,voxel,lods,load_s,import_s,tiles,bricks,bytes,verify\n"
      << layout.string() << ',' << sources.size() << ',' << spec.voxelSize << ',' << spec.lodCount
      << ',' << tLoad << ',' << tTotal << ',' << s.tiles << ',' << bricks << ',' << s.bytes << ','
      << (problem.empty() ? "ok" : "failed") << '\n';
  std::fputs(buf, stdout);
  return problem.empty() ? 0 : 1;
}

}  // namespace sdfstream::bench
