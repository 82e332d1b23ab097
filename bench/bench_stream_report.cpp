#include "bench/bench_stream_report.h"

#include <algorithm>
#include <cstdio>
#include <sstream>

namespace sdfstream::bench {
namespace {

std::string mib(std::size_t b) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.1f", double(b) / (1 << 20));
  return buf;
}
std::string fmt(double v, const char* f = "%.2f") {
  char buf[48];
  std::snprintf(buf, sizeof buf, f, v);
  return buf;
}

// The header and the fly-through table.
void writeFlights(std::ostringstream& md, const StreamBenchResults& r) {
  md << "# bench stream\n\nWorld: `" << r.world.string() << "` (" << r.tileFiles << " tile files, "
     << mib(r.warm.bytes) << " MiB), default route " << fmt(r.routeMetres, "%.0f") << " m, "
     << r.cascades << " cascades, atlas " << fmt(r.atlasMiB, "%.0f") << " MiB, " << r.loaderThreads
     << " loader threads, RAM cache " << mib(r.cacheBytes) << " MiB, upload budget "
     << mib(r.uploadBytesPerFrame)
     << " MiB/frame. No rendering (stack.update + takeDirtySlots per frame). All in one run.\n\n"
     << "## Fly-throughs (paced at 30 frames per wall-clock second)\n\n"
     << "Each starts with a fresh loader and stack, filled at the start of the route first (time "
        "shown, not counted in the figures), then flies; frames are capped at the route's "
        "length.\n\n"
     << "| speed | frames | initial fill (s) | resident fraction (mean over frames and cascades) | "
        "frames with a missing page | latency p50 / p99 (ms) | MB read | wall (s) | MB/s over wall "
        "| "
        "busy (s) | MB/s while busy |\n|---|---|---|---|---|---|---|---|---|---|---|\n";
  for (const Flight& f : r.flights)
    md << "| " << fmt(f.speed, "%.0f") << " m/s | " << f.frames << " | " << fmt(f.settleSeconds)
       << (f.settledAtStart ? "" : " (not settled)") << " | "
       << fmt(100.0 * f.summary.meanResidentFraction, "%.3f") << "% | "
       << f.summary.framesWithMissingPages << " (" << fmt(100.0 * f.missingFrameFraction(), "%.1f")
       << "%) | " << fmt(f.summary.latencyP50Ms, "%.1f") << " / "
       << fmt(f.summary.latencyP99Ms, "%.1f") << " | " << fmt(double(f.bytesRead) / 1e6, "%.1f")
       << " | " << fmt(f.wallSeconds) << " | " << fmt(f.throughputWall()) << " | "
       << fmt(f.busySeconds) << " | " << fmt(f.throughputBusy()) << " |\n";
  md << "\n\"Busy\" = the frame intervals at whose end a request was queued or a tile had "
        "completed "
        "since the previous frame (frame-granular approximation of time with loads in flight).\n\n";
}

// The sequential reads, and the loader's throughput against them.
void writeDiskLimit(std::ostringstream& md, const StreamBenchResults& r) {
  md << "## Disk limit: plain sequential read of every tile file (same run)\n\n"
     << "| pass | MB | s | MB/s |\n|---|---|---|---|\n"
     << "| first (cold-ish: the page cache was not dropped) | "
     << fmt(double(r.first.bytes) / 1e6, "%.1f") << " | " << fmt(r.first.seconds, "%.3f") << " | "
     << fmt(r.first.mbPerSecond(), "%.0f") << " |\n"
     << "| warm | " << fmt(double(r.warm.bytes) / 1e6, "%.1f") << " | "
     << fmt(r.warm.seconds, "%.3f") << " | " << fmt(r.warm.mbPerSecond(), "%.0f") << " |\n\n"
     << "| speed | loader MB/s while busy / sequential warm | / sequential first pass | loader "
        "MB/s "
        "over wall / sequential warm |\n|---|---|---|---|\n";
  for (const Flight& f : r.flights)
    md << "| " << fmt(f.speed, "%.0f") << " m/s | "
       << fmt(f.throughputBusy() / std::max(1e-9, r.warm.mbPerSecond()), "%.4f") << " | "
       << fmt(f.throughputBusy() / std::max(1e-9, r.first.mbPerSecond()), "%.4f") << " | "
       << fmt(f.throughputWall() / std::max(1e-9, r.warm.mbPerSecond()), "%.4f") << " |\n";
  md << "\nThe paced loader reads only what the camera needs, so its throughput is bounded by "
        "demand, not by the disk; the ratio shows the headroom left.\n\n";
}

// The long run's memory table; returns whether memory grew beyond allocator noise.
bool writeLongRun(std::ostringstream& md, const StreamBenchResults& r) {
  bool rssGrew = false;
  if (!r.samples.empty()) {
    const MemorySample& first = r.samples.front();
    const MemorySample& last = r.samples.back();
    const MemorySample* warm = &r.samples.back();
    for (const MemorySample& m : r.samples)
      if (m.frame >= 1000) {
        warm = &m;
        break;
      }
    std::size_t maxHeap = 0, maxHeapAfterWarm = 0, maxRss = 0, maxCache = 0, maxGpu = 0,
                maxRssAfterWarm = 0;
    for (const MemorySample& m : r.samples) {
      maxRss = std::max(maxRss, m.rss), maxCache = std::max(maxCache, m.cacheBytes);
      maxGpu = std::max(maxGpu, m.gpuBytes);
      maxHeap = std::max(maxHeap, m.heap);
      if (m.frame >= warm->frame) maxRssAfterWarm = std::max(maxRssAfterWarm, m.rss);
      if (m.frame >= warm->frame) maxHeapAfterWarm = std::max(maxHeapAfterWarm, m.heap);
    }
    // Growth is a trend, not a transient: the end of the run vs the end of warm-up (RSS), plus
    // the peak of live heap memory. Allocator caching makes RSS fluctuate by ±10% on its own.
    rssGrew = double(last.rss) > 1.1 * double(warm->rss) ||
              double(maxHeapAfterWarm) > 1.1 * double(warm->heap);
    md << "## Long run: " << r.longFrames << " frames unpaced, back and forth at 200 m/s ("
       << fmt(r.longSeconds, "%.1f") << " s wall)\n\n"
       << "| MiB | first (frame " << first.frame << ") | at frame " << warm->frame
       << " | last (frame " << last.frame << ") | max |\n|---|---|---|---|---|\n"
       << "| process RSS | " << mib(first.rss) << " | " << mib(warm->rss) << " | " << mib(last.rss)
       << " | " << mib(maxRss) << " |\n"
       << "| heap in use (mallinfo2) | " << mib(first.heap) << " | " << mib(warm->heap) << " | "
       << mib(last.heap) << " | " << mib(maxHeap) << " |\n"
       << "| loader RAM cache | " << mib(first.cacheBytes) << " | " << mib(warm->cacheBytes)
       << " | " << mib(last.cacheBytes) << " | " << mib(maxCache) << " |\n"
       << "| atlas + page tables (GPU) | " << mib(first.gpuBytes) << " | " << mib(warm->gpuBytes)
       << " | " << mib(last.gpuBytes) << " | " << mib(maxGpu) << " |\n\n"
       << "Samples every 500 frames in results.csv. RSS after frame " << warm->frame
       << " (warm-up) peaked at "
       << fmt(100.0 * (double(maxRssAfterWarm) / double(warm->rss) - 1.0), "%+.1f")
       << "% of its value there and ended at "
       << fmt(100.0 * (double(last.rss) / double(warm->rss) - 1.0), "%+.1f")
       << "%: " << (rssGrew ? "GREW by more than 10%" : "no growth beyond 10%")
       << ". Heap in use after frame " << warm->frame << " peaked at "
       << fmt(100.0 * (double(maxHeapAfterWarm) / double(warm->heap) - 1.0), "%+.1f")
       << "% of its value there (RSS above heap in use is memory the allocator keeps after "
          "free).\n\n";
  }

  return rssGrew;
}

void writeGoals(std::ostringstream& md, const StreamBenchResults& r, bool rssGrew) {
  const Flight& slow = r.flights.front();
  md << "## Goals\n\n"
     << "- Resident fraction ≥ 99% at 50 m/s: "
     << fmt(100.0 * slow.summary.meanResidentFraction, "%.3f") << "% — "
     << (slow.summary.meanResidentFraction >= 0.99 ? "met" : "NOT met") << ".\n"
     << "- No growth of RAM or GPU memory over a " << r.longFrames << "-frame fly-through: "
     << (r.samples.empty() ? "not measured (--long-frames 0)"
         : rssGrew
             ? "NOT met (RSS at the end or live heap > 10% above warm-up)"
             : "met (end-of-run RSS and peak live heap within 10% of warm-up; GPU bytes fixed)")
     << ".\n";
}

}  // namespace

std::string streamBenchCsv(const StreamBenchResults& r) {
  std::ostringstream csv;
  csv << "section,name,value\n";
  csv << "sequential,files," << r.tileFiles << "\nsequential,bytes," << r.warm.bytes
      << "\nsequential,first_pass_s," << r.first.seconds << "\nsequential,first_pass_mb_s,"
      << r.first.mbPerSecond() << "\nsequential,warm_pass_s," << r.warm.seconds
      << "\nsequential,warm_pass_mb_s," << r.warm.mbPerSecond() << '\n';
  for (const Flight& f : r.flights) {
    const std::string p = "fly_" + fmt(f.speed, "%.0f") + ",";
    const MetricsSummary& s = f.summary;
    csv << p << "frames," << f.frames << '\n'
        << p << "settled_at_start," << f.settledAtStart << '\n'
        << p << "initial_fill_s," << f.settleSeconds << '\n'
        << p << "initial_fill_bytes," << f.settleBytes << '\n'
        << p << "mean_resident_fraction," << s.meanResidentFraction << '\n'
        << p << "frames_with_missing_pages," << s.framesWithMissingPages << '\n'
        << p << "fraction_frames_with_missing_pages," << f.missingFrameFraction() << '\n'
        << p << "latency_p50_ms," << s.latencyP50Ms << '\n'
        << p << "latency_p99_ms," << s.latencyP99Ms << '\n'
        << p << "bytes_read," << f.bytesRead << '\n'
        << p << "bytes_uploaded," << s.bytesUploaded << '\n'
        << p << "wall_s," << f.wallSeconds << '\n'
        << p << "busy_s," << f.busySeconds << '\n'
        << p << "throughput_wall_mb_s," << f.throughputWall() << '\n'
        << p << "throughput_busy_mb_s," << f.throughputBusy() << '\n'
        << p << "ratio_busy_vs_warm_sequential,"
        << f.throughputBusy() / std::max(1e-9, r.warm.mbPerSecond()) << '\n'
        << p << "update_p99_ms," << s.updateP99Ms << '\n'
        << p << "peak_cache_bytes," << s.peakCacheBytes << '\n'
        << p << "failures," << s.failures << '\n';
  }
  csv << "long,frames," << r.longFrames << "\nlong,wall_s," << r.longSeconds << '\n';
  for (const MemorySample& m : r.samples)
    csv << "long_sample_" << m.frame << ",rss_bytes," << m.rss << "\nlong_sample_" << m.frame
        << ",heap_in_use_bytes," << m.heap << "\nlong_sample_" << m.frame << ",cache_bytes,"
        << m.cacheBytes << "\nlong_sample_" << m.frame << ",gpu_bytes," << m.gpuBytes
        << "\nlong_sample_" << m.frame << ",queued," << m.queued << '\n';

  return csv.str();
}

std::string streamBenchMarkdown(const StreamBenchResults& r) {
  std::ostringstream md;
  writeFlights(md, r);
  writeDiskLimit(md, r);
  const bool rssGrew = writeLongRun(md, r);
  writeGoals(md, r, rssGrew);
  return md.str();
}

}  // namespace sdfstream::bench
