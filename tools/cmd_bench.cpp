// sdfstream bench: the benchmarks' command table and the import benchmarks' flags (the
// benchmarks themselves are bench/). bench scroll, stream and gi parse their own flags in
// tools/cmd_bench_stream.cpp and tools/cmd_bench_gi.cpp.
#include <cstdio>
#include <string>

#include "bench/bench_import.h"
#include "bench/frame_loop_bench.h"
#include "core/error.h"
#include "tools/args.h"
#include "tools/commands.h"
#include "world/partition.h"

namespace sdfstream::cli {
namespace {

using Kind = InputErrorKind;

int benchImport(const Args& args) {
  bench::ImportBenchOptions o;
  o.mesh = args.value("--mesh").value_or(o.mesh.string());
  o.out = args.value("-o").value_or(o.out.string());
  o.runs = args.integer("--runs", o.runs, 1, 100);
  o.voxel = args.number("--voxel", 0.0);
  if (o.voxel < 0.0) throw InputError(Kind::Usage, "command line", "--voxel must be positive");
  return bench::runImportBench(o);
}

int benchWorld(const Args& args) {
  if (args.positional().size() != 2)
    throw InputError(Kind::Usage, "command line", "expected: sdfstream bench world LAYOUT.json");
  bench::WorldBenchOptions o;
  o.layout = args.positional()[1];
  o.out = args.value("-o").value_or(o.out.string());
  o.voxel = args.number("--voxel", o.voxel);
  o.lods = args.integer("--lods", o.lods, 1, PartitionSpec::kMaxLods);
  o.tileVoxels = args.integer("--tile-voxels", o.tileVoxels, 8, 1 << 16);
  o.maxMemoryBytes = std::size_t(args.number("--max-memory-gib", 8.0) * double(1ull << 30));
  return bench::runWorldBench(o);
}

int benchFrames(int argc, char** argv) {
  Args args(argc, argv, 3,
            {"--frames", "--warmup", "--objects", "--cascades", "--frames-in-flight", "--out"},
            {"--validation", "--help", "-h"});
  if (args.has("--help") || args.has("-h") || args.positional().size() != 1) {
    std::puts(
        "usage: sdfstream bench frames WORLD [--frames 300] [--warmup 30] [--objects 100]\n"
        "       [--cascades 4] [--frames-in-flight 2] [--validation] [--out out/bench/frames]\n"
        "The same streamed fly-through (default path over WORLD, 20 m/s at 60 frames/s, moving\n"
        "objects) twice: blocking GiSystem::update, then GiSystem::record into the benchmark's own\n"
        "command buffers with N frames in flight and one submission per frame. Reports frames/s\n"
        "and main-thread CPU ms per frame of both, and their ratios (summary.md).");
    return args.has("--help") || args.has("-h") ? 0 : 2;
  }
  bench::FrameLoopOptions o;
  o.world = args.positional()[0];
  o.out = args.value("--out").value_or("out/bench/frames");
  o.frames = args.integer("--frames", o.frames, 1, 100000);
  o.warmup = args.integer("--warmup", o.warmup, 0, 100000);
  o.objects = std::uint32_t(args.integer("--objects", int(o.objects), 0, 100000));
  o.cascades = args.integer("--cascades", o.cascades, 1, 8);
  o.framesInFlight = std::uint32_t(args.integer("--frames-in-flight", int(o.framesInFlight), 1, 8));
  o.validation = args.has("--validation");
  bench::runFrameLoopBench(o);
  return 0;
}

}  // namespace

int runBench(int argc, char** argv) {
  if (argc > 2 && std::string(argv[2]) == "frames") return benchFrames(argc, argv);
  // bench scroll, stream and gi have their own options (tools/cmd_bench_stream.cpp,
  // cmd_bench_gi.cpp).
  if (argc > 2 && std::string(argv[2]) == "scroll") return runBenchScroll(argc, argv);
  if (argc > 2 && std::string(argv[2]) == "stream") return runBenchStream(argc, argv);
  if (argc > 2 && std::string(argv[2]) == "gi") return runBenchGi(argc, argv);
  if (argc > 2 && std::string(argv[2]) == "host") return runBenchHost(argc, argv);
  Args args(argc, argv, 2,
            {"-o", "--mesh", "--voxel", "--runs", "--lods", "--tile-voxels", "--max-memory-gib"},
            {"--help", "-h"});
  const std::string what = args.positional().empty() ? "" : args.positional()[0];
  if (args.has("--help") || args.has("-h") || what.empty()) {
    std::puts(
        "usage: sdfstream bench import [--mesh FILE.obj] [--voxel V] [--runs 3] "
        "[-o out/bench/import]\n"
        "       sdfstream bench world LAYOUT.json [--voxel 1] [--lods 4] [-o out/bench/world]\n"
        "       sdfstream bench scroll WORLD [--moves N] [-o out/bench/scroll]\n"
        "       sdfstream bench stream WORLD [--frames 600] [--long-frames 10000] "
        "[-o out/bench/stream]\n"
        "       sdfstream bench gi [--quick] [--scenes a,b] [--out out/bench-gi] [--gpu-table]\n"
        "       sdfstream bench frames WORLD [--frames 300] [--objects 100] (see its --help)\n"
        "       sdfstream bench host [--objects 100,1000,10000] (see its --help)\n"
        "\n"
        "import: LOD-0 import of a mesh (default: glmark2's bunny; voxel default: largest extent\n"
        "        / 256, vdb_tool's default) through sdfstream's tiled importer vs\n"
        "        `vdb_tool -read MESH -mesh2ls voxel=V -write out.vdb`, side by side, best of N;\n"
        "        also sdfstream with 4 LODs. Reports time ratios, bricks/s, pack vs .vdb bytes.\n"
        "world:  imports a layout (terrain + instances, see generate-world) to OUT/pack with a\n"
        "        progress bar, then verifies it; reports time, tiles, bricks and size.\n"
        "scroll: a one-brick camera move vs a full rebuild of every cascade (see its --help).\n"
        "stream: fly-throughs at 50 and 200 m/s (residency, latency, read throughput) vs a plain\n"
        "        sequential read of the tile files, and a long run sampling memory (see its "
        "--help).\n"
        "gi:     run time vs error of the probe GI against a path-traced reference over a sweep "
        "of\n"
        "        the probe settings, plain DDGI as the baseline, Pareto fronts, and the probe-ray\n"
        "        traversal vs Embree/OpenVDB/NanoVDB on one frame's rays (see its --help).\n"
        "host:   the moving objects' host work per frame by part, no GPU (see its --help).\n"
        "All write results.csv and summary.md into the -o directory (gi: --out, default\n"
        "out/bench-gi, plus PNG plots).");
    return what.empty() && !args.has("--help") && !args.has("-h") ? 2 : 0;
  }
  if (what == "import") return benchImport(args);
  if (what == "world") return benchWorld(args);
  throw InputError(
      Kind::Usage, "command line",
      "unknown benchmark '" + what + "' (import, world, scroll, stream, gi, frames, host)");
}

}  // namespace sdfstream::cli
