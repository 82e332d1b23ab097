// sdfstream bench scroll and bench stream: their flags (the benchmarks are bench/bench_scroll.h
// and bench/bench_stream.h).
#include <cstdio>

#include "bench/bench_scroll.h"
#include "bench/bench_stream.h"
#include "core/error.h"
#include "tools/args.h"
#include "tools/commands.h"

namespace sdfstream::cli {

int runBenchScroll(int argc, char** argv) {
  Args args(argc, argv, 3, {"-o", "--moves", "--device", "--cascades"}, {"--help", "-h", "--cpu"});
  if (args.has("--help") || args.has("-h")) {
    std::puts(
        "usage: sdfstream bench scroll WORLD [-o DIR] [--moves N] [--cascades N] [--cpu]\n"
        "\n"
        "Compares a one-brick camera move (only the entering slab is filled) with a full rebuild\n"
        "of every cascade, same world, same warm tile cache, same run. Writes DIR/results.csv and\n"
        "DIR/summary.md (default DIR: out/bench/scroll).");
    return 0;
  }
  if (args.positional().size() != 1)
    throw InputError(InputErrorKind::Usage, "command line",
                     "expected: sdfstream bench scroll WORLD");
  bench::ScrollBenchOptions o;
  o.world = args.positional()[0];
  o.out = args.value("-o").value_or(o.out.string());
  o.moves = args.integer("--moves", o.moves, 1, 10000);
  o.cascades = args.integer("--cascades", o.cascades, 1, 8);
  o.device = deviceFromArgs(args);
  return bench::runScrollBench(o);
}

int runBenchStream(int argc, char** argv) {
  Args args(argc, argv, 3,
            {"-o", "--frames", "--long-frames", "--cascades", "--atlas-mib", "--upload-mib",
             "--loader-threads", "--cache-mib"},
            {"--help", "-h"});
  if (args.has("--help") || args.has("-h")) {
    std::puts(
        "usage: sdfstream bench stream WORLD [-o DIR] [--frames N] [--long-frames N]\n"
        "\n"
        "Streams a world pack into the cascade stack (CascadeStack + TileLoader + PackTileStore,\n"
        "no rendering, no GPU) along the default route, all in one run:\n"
        "  1. fly-throughs at 50 and 200 m/s, paced at 30 frames per wall-clock second, after an\n"
        "     initial fill at the start of the route: resident fraction of required bricks,\n"
        "     frames with a missing page, request-to-resident latency p50/p99, bytes read and the\n"
        "     loader's read throughput;\n"
        "  2. a plain sequential read (1 MiB ifstream reads) of every tile file, a first\n"
        "     (cold-ish: the page cache is not dropped) and a warm pass; the ratio of loader\n"
        "     throughput to it;\n"
        "  3. a long unpaced run back and forth at 200 m/s, sampling RSS (/proc/self/statm), the\n"
        "     loader's RAM cache and the atlas + page table bytes every 500 frames.\n"
        "Writes DIR/results.csv and DIR/summary.md (default DIR: out/bench/stream).\n"
        "\n"
        "  --frames N          frames per fly-through, at most the route's length (default 600)\n"
        "  --long-frames N     frames of the long run (default 10000)\n"
        "  --cascades N        cascades (default 6)\n"
        "  --atlas-mib N       brick atlas budget (default 96, as fly)\n"
        "  --upload-mib N      brick bytes uploaded per frame at most (default 16)\n"
        "  --loader-threads N  tile loader threads (default 2)\n"
        "  --cache-mib N       loader RAM cache of decoded tiles (default 512)");
    return 0;
  }
  if (args.positional().size() != 1)
    throw InputError(InputErrorKind::Usage, "command line",
                     "expected: sdfstream bench stream WORLD");
  bench::StreamBenchOptions o;
  o.world = args.positional()[0];
  o.out = args.value("-o").value_or(o.out.string());
  o.frames = args.integer("--frames", o.frames, 1, 1000000);
  o.longFrames = args.integer("--long-frames", o.longFrames, 0, 10000000);
  o.cascades = args.integer("--cascades", o.cascades, 1, 8);
  o.atlasMiB = args.number("--atlas-mib", o.atlasMiB);
  o.uploadMiB = args.number("--upload-mib", o.uploadMiB);
  o.loaderThreads = args.integer("--loader-threads", o.loaderThreads, 1, 64);
  o.cacheMiB = args.number("--cache-mib", o.cacheMiB);
  return bench::runStreamBench(o);
}

}  // namespace sdfstream::cli
