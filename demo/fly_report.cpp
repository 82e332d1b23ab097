#include "demo/fly_report.h"

#include <algorithm>
#include <cstdio>

#include "core/atomic_dir.h"
#include "core/stats.h"
#include "demo/plot.h"

namespace fs = std::filesystem;

namespace sdfstream {

void writeFlyPlots(const fs::path& dir, const std::vector<FrameMetrics>& frames) {
  static const glm::vec3 kColors[] = {{0.85f, 0.1f, 0.1f}, {0.1f, 0.45f, 0.85f}, {0.1f, 0.6f, 0.2f},
                                      {0.8f, 0.5f, 0.0f},  {0.5f, 0.2f, 0.7f},   {0.3f, 0.3f, 0.3f},
                                      {0.0f, 0.6f, 0.6f},  {0.6f, 0.4f, 0.3f}};
  Chart residency{"Residency per cascade", "frame", "resident / required bricks", {}};
  int cascades = frames.empty() ? 0 : int(frames.front().stream.cascades.size());
  for (int c = 0; c < cascades; ++c) {
    Series s{"cascade " + std::to_string(c), {}, {}, kColors[c % 8]};
    for (const auto& f : frames) {
      const auto& cs = f.stream.cascades[c];
      s.x.push_back(f.frame);
      s.y.push_back(cs.requiredBricks ? double(cs.residentBricks) / cs.requiredBricks : 1.0);
    }
    residency.series.push_back(std::move(s));
  }
  writeChartPng(dir / "residency.png", residency);

  Chart bytes{"Bytes streamed per frame", "frame", "MiB", {}};
  Series read{"read from disk", {}, {}, kColors[0]}, decoded{"decoded", {}, {}, kColors[1]},
      uploaded{"uploaded to the atlas", {}, {}, kColors[2]};
  const LoaderStats* prev = nullptr;
  for (const auto& f : frames) {
    double r = double(f.loader.bytesRead - (prev ? prev->bytesRead : 0)) / (1 << 20);
    double d = double(f.loader.bytesDecoded - (prev ? prev->bytesDecoded : 0)) / (1 << 20);
    read.x.push_back(f.frame), read.y.push_back(r);
    decoded.x.push_back(f.frame), decoded.y.push_back(d);
    uploaded.x.push_back(f.frame), uploaded.y.push_back(double(f.stream.bytesUploaded) / (1 << 20));
    prev = &f.loader;
  }
  bytes.series = {read, decoded, uploaded};
  writeChartPng(dir / "bytes.png", bytes);
}

void writeGiCsv(const fs::path& file, const std::vector<GiFrameMetrics>& frames) {
  std::string csv =
      "frame,light_ms,probe_ms,pages_relit,probes_updated,rays_traced,rays_cached,shade_ms,"
      "sample_ms,object_instances,object_region_ms,object_pages_relit,object_rays,object_hits,"
      "object_steps,object_pixels,relight_pending,relight_unlit,relight_staleness";
  // The probe update's passes one by one, named as ProbeField::lastTimings names them (the union
  // over all frames, in order of first appearance, so the columns stay fixed within a file).
  std::vector<std::string> passes;
  for (const auto& f : frames)
    for (const auto& t : f.probePasses)
      if (std::find(passes.begin(), passes.end(), t.name) == passes.end()) passes.push_back(t.name);
  for (const std::string& p : passes) csv += "," + p + "_ms";
  csv += "\n";
  char row[256];
  for (const auto& f : frames) {
    std::snprintf(row, sizeof row,
                  "%d,%.3f,%.3f,%u,%u,%u,%u,%.3f,%.3f,%u,%.3f,%u,%u,%u,%u,%zu,%u,%u,%u", f.frame,
                  f.gi.lightMilliseconds, f.gi.probeMilliseconds, f.gi.pagesRelit,
                  f.gi.probes.probesUpdated, f.gi.probes.raysTraced, f.gi.probes.raysCached,
                  f.shadeMilliseconds, f.sampleMilliseconds, f.gi.objectInstances,
                  f.gi.objectMilliseconds, f.gi.objectPagesRelit, f.gi.probes.objectRays,
                  f.gi.probes.objectHits, f.gi.probes.objectSteps, f.objectPixels,
                  f.gi.relight.pending, f.gi.relight.unlitPending, f.gi.relight.maxStalenessFrames);
    csv += row;
    for (const std::string& p : passes) {
      double ms = 0.0;
      for (const auto& t : f.probePasses)
        if (t.name == p) ms += t.milliseconds;
      std::snprintf(row, sizeof row, ",%.3f", ms);
      csv += row;
    }
    csv += "\n";
  }
  writeFileAtomically(file, csv.data(), csv.size());
}

std::string giSummaryMarkdown(const std::vector<GiFrameMetrics>& frames, bool gi,
                              const probe::ProbeFieldSettings& probes, std::size_t probeBytes) {
  std::vector<double> probe, light, shade, sample, updated, traced;
  for (const auto& f : frames) {
    probe.push_back(f.gi.probeMilliseconds);
    light.push_back(f.gi.lightMilliseconds);
    updated.push_back(f.gi.probes.probesUpdated);
    traced.push_back(f.gi.probes.raysTraced);
    if (f.shadeMilliseconds > 0.0) shade.push_back(f.shadeMilliseconds);
    if (f.sampleMilliseconds > 0.0) sample.push_back(f.sampleMilliseconds);
  }
  char text[2048];
  if (!gi) {
    std::snprintf(text, sizeof text,
                  "\n## GI\n\nOff (--gi off or --cpu): frames show direct light only. Shade pass "
                  "(trace + direct light; GPU time, or wall time of the CPU reference) of rendered "
                  "frames: mean %.2f ms, p99 %.2f ms.\n",
                  mean(shade), percentile(shade, 0.99));
    return text;
  }
  std::snprintf(
      text, sizeof text,
      "\n## GI\n\nGPU time per frame (gi.csv has every frame): the light cache relights pages "
      "that streamed in or changed; the probe field (one 17^3 volume per cascade, %u rays per "
      "probe, %.1f MiB) updates within its ray budget of %u rays per frame.\n\n"
      "| pass | mean ms | p50 ms | p99 ms | max ms |\n|---|---|---|---|---|\n"
      "| light cache | %.2f | %.2f | %.2f | %.2f |\n"
      "| probe update (all passes) | %.2f | %.2f | %.2f | %.2f |\n"
      "| shade_primary (rendered frames) | %.2f | %.2f | %.2f | %.2f |\n"
      "| probe_sample (rendered frames) | %.2f | %.2f | %.2f | %.2f |\n\n"
      "Probes updated per frame: mean %.0f; probe rays sphere-traced per frame: mean %.0f (the "
      "rest come from the hit cache).\n",
      probes.raysPerProbe, double(probeBytes) / (1 << 20), probes.rayBudget, mean(light),
      percentile(light, 0.5), percentile(light, 0.99), percentile(light, 1.0), mean(probe),
      percentile(probe, 0.5), percentile(probe, 0.99), percentile(probe, 1.0), mean(shade),
      percentile(shade, 0.5), percentile(shade, 0.99), percentile(shade, 1.0), mean(sample),
      percentile(sample, 0.5), percentile(sample, 0.99), percentile(sample, 1.0), mean(updated),
      mean(traced));
  return text;
}

std::string relightSummaryMarkdown(const std::vector<GiFrameMetrics>& frames, bool gi,
                                   std::uint32_t relightPageBudget) {
  if (!gi || frames.empty()) return {};
  std::vector<double> relit, pending, unlit, stale;
  for (const auto& f : frames) {
    relit.push_back(f.gi.pagesRelit);
    pending.push_back(f.gi.relight.pending);
    unlit.push_back(f.gi.relight.unlitPending);
    stale.push_back(f.gi.relight.maxStalenessFrames);
  }
  const std::string budget = relightPageBudget == kRelightEveryPage
                                 ? std::string("every out-of-date page each frame")
                                 : std::to_string(relightPageBudget) + " pages per frame";
  char text[1024];
  std::snprintf(text, sizeof text,
                "\n## Light cache relight\n\nBudget: %s (--relight-pages; new bricks first, then "
                "the longest out of date). Pages relit per frame: mean %.0f, max %.0f. Left out "
                "of date after the frame: mean %.0f, max %.0f (never lit: max %.0f). Staleness "
                "(frames the longest-waiting page has shown old light): p50 %.0f, p99 %.0f, max "
                "%.0f.\n",
                budget.c_str(), mean(relit), percentile(relit, 1.0), mean(pending),
                percentile(pending, 1.0), percentile(unlit, 1.0), percentile(stale, 0.5),
                percentile(stale, 0.99), percentile(stale, 1.0));
  return text;
}

std::string objectSummaryMarkdown(const std::vector<GiFrameMetrics>& frames, bool gi) {
  std::vector<double> regions, relit, rays, hits, pixels;
  std::uint32_t instances = 0;
  for (const auto& f : frames) {
    instances = std::max(instances, f.gi.objectInstances);
    regions.push_back(f.gi.objectMilliseconds);
    relit.push_back(f.gi.objectPagesRelit);
    rays.push_back(f.gi.probes.objectRays);
    hits.push_back(f.gi.probes.objectHits);
    if (f.shadeMilliseconds > 0.0) pixels.push_back(double(f.objectPixels));
  }
  if (instances == 0) return {};
  char text[1024];
  std::snprintf(
      text, sizeof text,
      "\n## Moving objects\n\n%u scripted objects along the path (--objects), moved every frame. "
      "Region lists (object_regions passes): mean %.2f ms, p99 %.2f ms per frame; light-cache "
      "pages put out of date because objects moved: mean %.0f per frame (relit within the "
      "budget above, inside the light cache time); probe rays that searched the objects: mean %.0f "
      "per frame, of which %.0f hit one%s; "
      "pixels showing an object in the rendered frames: mean %.0f. Their search in primary "
      "rays and shadow rays is inside shade_primary's time (gi.csv has every frame).\n",
      instances, mean(regions), percentile(regions, 0.99), mean(relit), mean(rays), mean(hits),
      gi ? "" : " (GI off: none)", mean(pixels));
  return text;
}

}  // namespace sdfstream
