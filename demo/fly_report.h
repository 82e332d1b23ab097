// What `sdfstream fly` writes besides its frames: gi.csv (the GI passes of every frame),
// the GI and moving-object sections of summary.md, and the residency and bytes charts
// (metrics.csv and the streaming summary are streaming/stream_metrics.h's).
#pragma once

#include <cstddef>
#include <filesystem>
#include <string>
#include <vector>

#include "demo/gi_shading.h"
#include "streaming/stream_metrics.h"

namespace sdfstream {

// GI cost of one frame (gi.csv): the passes GiRenderer ran.
struct GiFrameMetrics {
  int frame = 0;
  GiFrameStats gi;
  std::vector<gpu::PassTiming> probePasses;
  double shadeMilliseconds = 0.0;   // 0 when the frame was not rendered
  double sampleMilliseconds = 0.0;  // 0 when the frame was not rendered
  std::size_t objectPixels = 0;     // rendered frames: pixels showing a moving object
};

// One row per frame; the probe passes get a column each. Written atomically.
void writeGiCsv(const std::filesystem::path& file, const std::vector<GiFrameMetrics>& frames);

// The summary's "GI" section: pass times (mean, p50, p99, max) and probe work; with gi false, one
// line on the direct-only shade pass.
std::string giSummaryMarkdown(const std::vector<GiFrameMetrics>& frames, bool gi,
                              const probe::ProbeFieldSettings& probes, std::size_t probeBytes);

// The light cache's relight queue (LightRelightQueue): pages relit per frame against the budget,
// pages left out of date and their staleness in frames (empty with GI off).
std::string relightSummaryMarkdown(const std::vector<GiFrameMetrics>& frames, bool gi,
                                   std::uint32_t relightPageBudget);

// The moving objects' share of the frame (empty without objects).
std::string objectSummaryMarkdown(const std::vector<GiFrameMetrics>& frames, bool gi);

// DIR/residency.png (resident / required bricks per cascade) and DIR/bytes.png (MiB read,
// decoded and uploaded per frame).
void writeFlyPlots(const std::filesystem::path& dir, const std::vector<FrameMetrics>& frames);

}  // namespace sdfstream
