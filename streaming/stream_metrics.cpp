#include "streaming/stream_metrics.h"

#include <algorithm>
#include <cstdio>
#include <sstream>

#include "core/atomic_dir.h"
#include "core/stats.h"

namespace sdfstream {

MetricsSummary summarize(const std::vector<FrameMetrics>& frames) {
  MetricsSummary s;
  s.frames = int(frames.size());
  std::vector<double> latencies, updates;
  double fractionSum = 0.0;
  int fractionCount = 0;
  for (const FrameMetrics& f : frames) {
    if (f.stream.missingPages > 0) ++s.framesWithMissingPages;
    latencies.insert(latencies.end(), f.loader.latenciesMs.begin(), f.loader.latenciesMs.end());
    updates.push_back(f.updateMilliseconds);
    s.bytesUploaded += f.stream.bytesUploaded;
    s.peakCacheBytes = std::max(s.peakCacheBytes, f.loader.cacheBytes);
    s.gpuBytes = std::max(s.gpuBytes, f.gpuBytes);
    for (const auto& c : f.stream.cascades)
      if (c.requiredBricks > 0) {
        fractionSum += double(c.residentBricks) / c.requiredBricks;
        ++fractionCount;
      }
  }
  if (!frames.empty()) {
    const LoaderStats& last = frames.back().loader;
    s.tilesLoaded = last.tilesLoaded;
    s.bytesRead = last.bytesRead;
    s.bytesDecoded = last.bytesDecoded;
    s.failures = last.failures;
    s.retries = last.retries;
    s.cancelled = last.cancelled;
  }
  s.latencyP50Ms = percentile(latencies, 0.5);
  s.latencyP99Ms = percentile(latencies, 0.99);
  s.updateP50Ms = percentile(updates, 0.5);
  s.updateP99Ms = percentile(updates, 0.99);
  s.meanResidentFraction = fractionCount ? fractionSum / fractionCount : 1.0;
  return s;
}

void writeMetricsCsv(const std::filesystem::path& file, const std::vector<FrameMetrics>& frames) {
  std::ostringstream out;
  int cascades = frames.empty() ? 0 : int(frames.front().stream.cascades.size());
  out << "frame,seconds,camera_x,camera_y,camera_z";
  for (int c = 0; c < cascades; ++c)
    out << ",c" << c << "_resident,c" << c << "_required,c" << c << "_missing,c" << c << "_changed";
  out << ",missing_pages,failed_pages,atlas_full_pages,atlas_slots_used,bytes_uploaded,"
         "tiles_loaded_total,bytes_read_total,bytes_decoded_total,latency_p50_ms,latency_max_ms,"
         "cache_bytes,gpu_bytes,update_ms,trace_ms\n";
  char buf[64];
  for (const FrameMetrics& f : frames) {
    std::snprintf(buf, sizeof buf, "%d,%.4f,%.3f,%.3f,%.3f", f.frame, f.seconds, f.camera.x,
                  f.camera.y, f.camera.z);
    out << buf;
    for (const auto& c : f.stream.cascades)
      out << ',' << c.residentBricks << ',' << c.requiredBricks << ',' << c.missingPages << ','
          << c.pagesChanged;
    double lp50 = 0, lmax = 0;
    if (!f.loader.latenciesMs.empty()) {
      std::vector<double> l = f.loader.latenciesMs;
      std::sort(l.begin(), l.end());
      lp50 = l[l.size() / 2];
      lmax = l.back();
    }
    out << ',' << f.stream.missingPages << ',' << f.stream.failedPages << ','
        << f.stream.atlasFullPages << ',' << f.stream.atlasSlotsUsed << ','
        << f.stream.bytesUploaded << ',' << f.loader.tilesLoaded << ',' << f.loader.bytesRead
        << ',' << f.loader.bytesDecoded << ',' << lp50 << ',' << lmax << ','
        << f.loader.cacheBytes << ',' << f.gpuBytes << ',' << f.updateMilliseconds << ','
        << f.traceMilliseconds << '\n';
  }
  std::string text = out.str();
  writeFileAtomically(file, text.data(), text.size());
}

std::string summaryMarkdown(const MetricsSummary& s) {
  std::ostringstream o;
  auto mib = [](double b) { return b / double(1 << 20); };
  o << "| metric | value |\n|---|---|\n"
    << "| frames | " << s.frames << " |\n"
    << "| frames with any missing page | " << s.framesWithMissingPages << " |\n"
    << "| mean resident fraction (resident / required, per cascade) | " << s.meanResidentFraction
    << " |\n"
    << "| request → resident latency p50 / p99 | " << s.latencyP50Ms << " / " << s.latencyP99Ms
    << " ms |\n"
    << "| tiles loaded | " << s.tilesLoaded << " |\n"
    << "| MiB read / decoded / uploaded | " << mib(s.bytesRead) << " / " << mib(s.bytesDecoded)
    << " / " << mib(s.bytesUploaded) << " |\n"
    << "| load retries / failures / cancelled requests | " << s.retries << " / " << s.failures
    << " / " << s.cancelled << " |\n"
    << "| frame-thread update p50 / p99 | " << s.updateP50Ms << " / " << s.updateP99Ms
    << " ms |\n"
    << "| peak RAM tile cache | " << mib(s.peakCacheBytes) << " MiB |\n"
    << "| GPU memory (page tables + atlas) | " << mib(s.gpuBytes) << " MiB |\n";
  return o.str();
}

}  // namespace sdfstream
