// Per-frame streaming metrics and their summary: residency per cascade,
// bytes read/decoded/uploaded, request-to-resident latency, frames with a missing page, memory.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "streaming/cascade_stack.h"
#include "streaming/tile_loader.h"

namespace sdfstream {

struct FrameMetrics {
  int frame = 0;
  double seconds = 0.0;              // simulated time along the path
  glm::dvec3 camera{0.0};
  StreamFrameStats stream;           // residency, uploads, missing pages
  LoaderStats loader;                // cumulative counters + this frame's latency samples
  std::size_t gpuBytes = 0;          // page tables + atlas
  double updateMilliseconds = 0.0;   // CPU time of CascadeStack::update (frame thread)
  double traceMilliseconds = 0.0;    // GPU trace time when the frame was rendered, else 0
};

struct MetricsSummary {
  int frames = 0;
  int framesWithMissingPages = 0;
  double latencyP50Ms = 0.0, latencyP99Ms = 0.0;
  std::uint64_t tilesLoaded = 0, bytesRead = 0, bytesDecoded = 0, bytesUploaded = 0;
  std::uint64_t failures = 0, retries = 0, cancelled = 0;
  double meanResidentFraction = 0.0;  // resident / required over cascades and frames
  double updateP50Ms = 0.0, updateP99Ms = 0.0;
  std::size_t peakCacheBytes = 0, gpuBytes = 0;
};

MetricsSummary summarize(const std::vector<FrameMetrics>& frames);

// One row per frame; columns named in the header. Written atomically.
void writeMetricsCsv(const std::filesystem::path& file, const std::vector<FrameMetrics>& frames);

// The summary as a markdown table (for reports).
std::string summaryMarkdown(const MetricsSummary& summary);

}  // namespace sdfstream
