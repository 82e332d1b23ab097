// The import benchmarks of `sdfstream bench`, each writing results.csv and summary.md into its
// output directory:
//   import: our tiled importer vs OpenVDB's vdb_tool -mesh2ls on the same mesh and voxel, side by
//           side in one invocation, best of N each (also ours with 4 LODs).
//   world:  a layout (e.g. from generate-world) through loadLayoutSources + importPack, one timed
//           run with a progress bar, then verified; reports tiles, bricks, bytes.
#pragma once

#include <cstddef>
#include <filesystem>

namespace sdfstream::bench {

struct ImportBenchOptions {
  std::filesystem::path mesh = "/usr/share/glmark2/models/bunny.obj";  // an OBJ
  std::filesystem::path out = "out/bench/import";
  int runs = 3;
  double voxel = 0.0;  // metres; 0: vdb_tool's default (the largest extent spans 256 voxels)
};
// Returns 0. vdb_tool missing is reported, not an error.
int runImportBench(const ImportBenchOptions& options);

struct WorldBenchOptions {
  std::filesystem::path layout;  // a layout.json
  std::filesystem::path out = "out/bench/world";
  double voxel = 1.0;  // LOD-0 voxel, metres
  int lods = 4;
  int tileVoxels = 128;
  std::size_t maxMemoryBytes = std::size_t(8) << 30;  // importer memory limit
};
// Returns 0, or 1 when the written pack fails verification.
int runWorldBench(const WorldBenchOptions& options);

}  // namespace sdfstream::bench
