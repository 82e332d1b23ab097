// `sdfstream bench stream`: fly-throughs over a world pack at 50 and 200 m/s
// streaming into the cascade stack (no rendering, no GPU), measured against the disk's physical
// limit (a plain sequential read of the same tile files, same run), plus a long unpaced run
// sampling RSS, the loader's RAM cache and the atlas bytes to show that memory does not grow.
// Writes results.csv and summary.md (bench/bench_stream_report.h).
#pragma once

#include <filesystem>

namespace sdfstream::bench {

struct StreamBenchOptions {
  std::filesystem::path world;  // a world pack
  std::filesystem::path out = "out/bench/stream";
  int frames = 600;        // per fly-through, at most the route's length
  int longFrames = 10000;  // of the long run (0: none)
  int cascades = 6;
  double atlasMiB = 96.0;   // brick atlas budget, as fly
  double uploadMiB = 16.0;  // brick bytes uploaded per frame at most
  int loaderThreads = 2;
  double cacheMiB = 512.0;  // loader RAM cache of decoded tiles
};

// Returns 0. Throws InputError for a bad pack or an unreadable tile file.
int runStreamBench(const StreamBenchOptions& options);

}  // namespace sdfstream::bench
