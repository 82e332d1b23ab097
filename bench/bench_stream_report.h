// What `sdfstream bench stream` measured (bench/bench_stream.h), and how it is written:
// results.csv (section, name, value rows) and summary.md (fly-throughs, the disk limit, the long
// run's memory, the goals).
#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "streaming/stream_metrics.h"

namespace sdfstream::bench {

// A plain sequential read of every tile file of the pack.
struct SequentialRead {
  std::uint64_t bytes = 0;
  double seconds = 0.0;
  double mbPerSecond() const { return seconds > 0 ? double(bytes) / 1e6 / seconds : 0.0; }
};

// One paced fly-through.
struct Flight {
  double speed = 0.0;
  int frames = 0;
  bool settledAtStart = false;
  double settleSeconds = 0.0;  // initial fill at the start of the route (not in the figures)
  std::uint64_t settleBytes = 0;
  MetricsSummary summary;       // over the flight's frames only
  std::uint64_t bytesRead = 0;  // during the flight
  double wallSeconds = 0.0;     // whole flight
  double busySeconds = 0.0;     // frame intervals with a request queued or a tile completed
  double missingFrameFraction() const {
    return frames ? double(summary.framesWithMissingPages) / frames : 0;
  }
  double throughputWall() const {
    return wallSeconds > 0 ? double(bytesRead) / 1e6 / wallSeconds : 0;
  }
  double throughputBusy() const {
    return busySeconds > 0 ? double(bytesRead) / 1e6 / busySeconds : 0;
  }
};

// Memory of the long run at one frame.
struct MemorySample {
  int frame = 0;
  std::size_t rss = 0, heap = 0, cacheBytes = 0, cachedTiles = 0, gpuBytes = 0, queued = 0;
};

// Everything one run measured, and what it was run on.
struct StreamBenchResults {
  std::filesystem::path world;
  std::size_t tileFiles = 0;
  double routeMetres = 0.0;
  int cascades = 0, loaderThreads = 0;
  double atlasMiB = 0.0;  // as allocated: whole slots
  std::size_t cacheBytes = 0, uploadBytesPerFrame = 0;
  SequentialRead first, warm;   // the first (cold-ish) and the second pass
  std::vector<Flight> flights;  // 50 m/s first
  int longFrames = 0;
  double longSeconds = 0.0;
  std::vector<MemorySample> samples;  // every 500 frames of the long run
};

std::string streamBenchCsv(const StreamBenchResults& r);
std::string streamBenchMarkdown(const StreamBenchResults& r);

}  // namespace sdfstream::bench
