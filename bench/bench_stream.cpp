#include "bench/bench_stream.h"

#include <malloc.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <thread>

#include "bench/bench_stream_report.h"
#include "core/atomic_dir.h"
#include "core/error.h"
#include "core/stopwatch.h"
#include "demo/fly_path.h"
#include "streaming/cascade_stack.h"
#include "streaming/pack_store.h"
#include "streaming/stream_metrics.h"

namespace fs = std::filesystem;

namespace sdfstream::bench {
namespace {
using Clock = std::chrono::steady_clock;

std::size_t residentSetBytes() {
  std::ifstream statm("/proc/self/statm");
  std::size_t size = 0, resident = 0;
  statm >> size >> resident;
  return resident * std::size_t(sysconf(_SC_PAGESIZE));
}

// Bytes the allocator has handed out and not had back (all arenas, plus mmapped chunks): tells a
// leak (grows) from memory the allocator keeps after free (RSS only).
std::size_t heapInUseBytes() {
  struct mallinfo2 mi = mallinfo2();
  return mi.uordblks + mi.hblkhd;
}

// A plain sequential read of every tile file of the pack, in manifest order, 1 MiB at a time.
SequentialRead readAllTiles(const fs::path& world, const PackManifest& m) {
  std::vector<char> buffer(std::size_t(1) << 20);
  SequentialRead r;
  const auto start = Clock::now();
  for (const TileEntry& e : m.tiles) {
    std::ifstream in(world / e.file, std::ios::binary);
    if (!in) throw InputError(InputErrorKind::Io, (world / e.file).string(), "cannot open");
    while (in) {
      in.read(buffer.data(), std::streamsize(buffer.size()));
      r.bytes += std::uint64_t(in.gcount());
    }
  }
  r.seconds = secondsSince(start);
  return r;
}

struct StreamConfig {
  StreamingOptions so;
  LoaderOptions lo;
};

glm::dvec3 lookDirection(const FlyPath& path, double s) {
  return glm::normalize(path.direction(s) + glm::dvec3(0.0, -0.25, 0.0));
}

// Settles the stack at the start of the route (as if the world had been loaded at spawn), then
// flies `frames` frames at `speed`, paced at 30 frames per wall-clock second like `fly`.
Flight fly(const PackTileStore& store, const FlyPath& path, double speed, int frames,
           const StreamConfig& config) {
  TileLoader loader(store, config.lo);
  CascadeStack stack(store, loader, config.so);
  Flight f;
  f.speed = speed;
  f.frames = frames;
  const auto settleStart = Clock::now();
  for (int round = 0; round < 2000 && !f.settledAtStart; ++round) {
    stack.update(path.position(0.0), lookDirection(path, 0.0));
    stack.takeDirtySlots();
    f.settledAtStart = stack.settled();
    if (!f.settledAtStart) loader.waitIdle();
  }
  f.settleSeconds = secondsSince(settleStart);
  LoaderStats base = loader.takeStats();  // also drops the fill's latency samples
  f.settleBytes = base.bytesRead;

  std::vector<FrameMetrics> metrics;
  metrics.reserve(std::size_t(frames));
  const auto start = Clock::now();
  auto previousFrameEnd = start;
  std::uint64_t previousBytes = base.bytesRead;
  for (int i = 0; i < frames; ++i) {
    const double t = i / 30.0;
    std::this_thread::sleep_until(start + std::chrono::microseconds(std::int64_t(t * 1e6)));
    const double s = speed * t;
    FrameMetrics m;
    m.frame = i;
    m.seconds = t;
    m.camera = path.position(s);
    const auto t0 = Clock::now();
    m.stream = stack.update(m.camera, lookDirection(path, s));
    m.updateMilliseconds = millisecondsSince(t0);
    stack.takeDirtySlots();
    m.gpuBytes =
        stack.atlasBytes() + std::size_t(stack.cascadeCount()) * layout::kCascadePageCount * 4;
    m.loader = loader.takeStats();
    const auto now = Clock::now();
    if (m.loader.queued > 0 || m.loader.bytesRead > previousBytes)
      f.busySeconds += std::chrono::duration<double>(now - previousFrameEnd).count();
    previousFrameEnd = now;
    previousBytes = m.loader.bytesRead;
    metrics.push_back(std::move(m));
  }
  f.wallSeconds = secondsSince(start);
  f.summary = summarize(metrics);
  f.bytesRead = metrics.empty() ? 0 : metrics.back().loader.bytesRead - base.bytesRead;
  return f;
}

// Unpaced, back and forth along the route at `speed`; samples memory every `every` frames.
std::vector<MemorySample> longRun(const PackTileStore& store, const FlyPath& path, double speed,
                                  int frames, int every, const StreamConfig& config,
                                  double& wallSeconds) {
  TileLoader loader(store, config.lo);
  CascadeStack stack(store, loader, config.so);
  const double length = path.length();
  std::vector<MemorySample> samples;
  const auto start = Clock::now();
  for (int i = 0; i <= frames; ++i) {
    double s = std::fmod(speed * i / 30.0, 2.0 * length);
    glm::dvec3 look = lookDirection(path, s);
    if (s > length) {
      s = 2.0 * length - s;
      look = glm::normalize(-path.direction(s) + glm::dvec3(0.0, -0.25, 0.0));
    }
    if (i < frames) {
      stack.update(path.position(s), look);
      stack.takeDirtySlots();
    }
    LoaderStats ls = loader.takeStats();  // every frame, so latency samples do not pile up
    if (i % every == 0 || i == frames) {
      MemorySample m;
      m.frame = i;
      m.rss = residentSetBytes();
      m.heap = heapInUseBytes();
      m.cacheBytes = ls.cacheBytes;
      m.cachedTiles = ls.cachedTiles;
      m.queued = ls.queued;
      m.gpuBytes =
          stack.atlasBytes() + std::size_t(stack.cascadeCount()) * layout::kCascadePageCount * 4;
      samples.push_back(m);
      std::fprintf(
          stderr,
          "  long run frame %d/%d: RSS %.1f MiB, heap %.1f MiB, cache %.1f MiB, queued %zu\n", i,
          frames, double(m.rss) / (1 << 20), double(m.heap) / (1 << 20),
          double(m.cacheBytes) / (1 << 20), m.queued);
    }
  }
  wallSeconds = secondsSince(start);
  return samples;
}

StreamConfig streamConfig(const StreamBenchOptions& o) {
  StreamConfig config;
  config.so.cascades = o.cascades;
  const std::size_t slotBytes = 4 * (layout::kBrickDistanceWords + 2 * layout::kBrickMaterialCount);
  config.so.atlasSlots = std::uint32_t(o.atlasMiB * double(1 << 20) / slotBytes);
  config.so.uploadBytesPerFrame = std::size_t(o.uploadMiB * double(1 << 20));
  config.lo.threads = o.loaderThreads;
  config.lo.cacheBytes = std::size_t(o.cacheMiB * double(1 << 20));
  return config;
}

}  // namespace

int runStreamBench(const StreamBenchOptions& o) {
  PackTileStore store(o.world);
  const PackManifest& manifest = store.manifest();
  const FlyPath path = defaultFlyPath(manifest.boundsMin, manifest.boundsMax);
  const StreamConfig config = streamConfig(o);
  const std::size_t slotBytes = 4 * (layout::kBrickDistanceWords + 2 * layout::kBrickMaterialCount);

  StreamBenchResults r;
  r.world = o.world;
  r.tileFiles = manifest.tiles.size();
  r.routeMetres = path.length();
  r.cascades = config.so.cascades;
  r.loaderThreads = config.lo.threads;
  r.atlasMiB = double(config.so.atlasSlots) * double(slotBytes) / (1 << 20);
  r.cacheBytes = config.lo.cacheBytes;
  r.uploadBytesPerFrame = config.so.uploadBytesPerFrame;
  r.longFrames = o.longFrames;
  std::printf("bench stream: %s, route %.0f m, %d cascades, atlas %.0f MiB, %d loader threads\n",
              o.world.c_str(), r.routeMetres, r.cascades, r.atlasMiB, r.loaderThreads);

  // 2 first: the first pass sees whatever the page cache holds (nothing is dropped), the second
  // is warm, as the fly-throughs that follow will be.
  std::fprintf(stderr, "  sequential read of every tile file (2 passes)...\n");
  r.first = readAllTiles(o.world, manifest);
  r.warm = readAllTiles(o.world, manifest);

  for (double speed : {50.0, 200.0}) {
    const int n = std::max(1, std::min(o.frames, int(r.routeMetres / speed * 30.0)));
    std::fprintf(stderr, "  fly-through at %.0f m/s, %d frames (%.1f s)...\n", speed, n, n / 30.0);
    r.flights.push_back(fly(store, path, speed, n, config));
  }

  if (o.longFrames > 0) {
    std::fprintf(stderr, "  long run: %d frames unpaced at 200 m/s...\n", o.longFrames);
    r.samples = longRun(store, path, 200.0, o.longFrames, 500, config, r.longSeconds);
  }

  fs::create_directories(o.out);
  const std::string csvText = streamBenchCsv(r), mdText = streamBenchMarkdown(r);
  writeFileAtomically(o.out / "results.csv", csvText.data(), csvText.size());
  writeFileAtomically(o.out / "summary.md", mdText.data(), mdText.size());
  std::fputs(mdText.c_str(), stdout);
  std::printf("wrote %s and %s\n", (o.out / "results.csv").c_str(), (o.out / "summary.md").c_str());
  return 0;
}

}  // namespace sdfstream::bench
