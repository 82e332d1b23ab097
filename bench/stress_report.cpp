#include "bench/stress_report.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <utility>

#include "bench/report_format.h"
#include "core/atomic_dir.h"
#include "core/stats.h"
#include "demo/plot.h"

namespace sdfstream::bench::stress {
namespace {

namespace fs = std::filesystem;

constexpr std::uint32_t kGoalObjects = 10000;
constexpr double kGoalRatio = 2.0;  // regions + probe update vs static-only (stretch 1.5)
// The other targets: (objects, largest cost ratio) and the host time at kGoalObjects.
constexpr std::pair<std::uint32_t, double> kCountGoals[] = {{100, 1.1}, {1000, 1.3}, {10000, 2.0}};
constexpr double kGoalLightRatio = 3.0;  // ... with the light cache, at kGoalObjects
constexpr double kGoalHostMs = 2.0;

double medianOf(const StressRun& run, const std::function<double(const StressFrame&)>& get) {
  std::vector<double> v;
  v.reserve(run.frames.size());
  for (const StressFrame& f : run.frames) v.push_back(get(f));
  return percentile(std::move(v), 0.5);
}

const StressRun* findRun(const std::vector<StressRun>& runs, Mode mode, std::uint32_t objects) {
  for (const StressRun& r : runs)
    if (r.mode == mode && (!hasObjects(mode) || r.objects == objects)) return &r;
  return nullptr;
}

bool measured(const StressRun* r) { return r && r->skipped.empty() && !r->frames.empty(); }

// Markdown cell of a count with thousands separators (10,000).
std::string withCommas(std::uint64_t n) {
  const std::string digits = std::to_string(n);
  std::string s;
  for (std::size_t i = 0; i < digits.size(); ++i) {
    if (i > 0 && (digits.size() - i) % 3 == 0) s += ',';
    s += digits[i];
  }
  return s;
}

std::vector<std::uint32_t> objectCounts(const std::vector<StressRun>& runs) {
  std::vector<std::uint32_t> counts;
  for (const StressRun& r : runs)
    if (hasObjects(r.mode) && std::find(counts.begin(), counts.end(), r.objects) == counts.end())
      counts.push_back(r.objects);
  std::sort(counts.begin(), counts.end());
  return counts;
}

void writeText(const fs::path& file, const std::string& text) {
  writeFileAtomically(file, text.data(), text.size());
}

void writeResultsCsv(const fs::path& file, const std::vector<StressRun>& runs) {
  const RunSummary base = measured(findRun(runs, Mode::Static, 0))
                              ? summarize(*findRun(runs, Mode::Static, 0))
                              : RunSummary{};
  std::string csv =
      "objects,mode,skipped,frames,region_count_ms,region_scan_ms,region_fill_ms,region_ms,"
      "region_us_per_instance,probe_ms,probe_p99_ms,cost_ms,cost_vs_static,probe_trace_ms,"
      "trace_extra_ms,light_ms,pages_relit,object_pages_relit,probes_updated,rays_traced,"
      "rays_traced_total,object_rays,object_hits,object_steps,steps_per_object_ray,host_ms,"
      "nonfinite_texels,irradiance_checks,validation_messages,wall_s,card_light_ms,card_relit,"
      "card_stale_frames,card_mib\n";
  char row[1024];
  for (const StressRun& r : runs) {
    if (!r.skipped.empty()) {
      csv += std::to_string(r.objects) + "," + modeName(r.mode) + ",\"" + r.skipped + "\"" +
             std::string(31, ',') + "\n";
      continue;
    }
    const RunSummary s = summarize(r);
    std::snprintf(
        row, sizeof row,
        "%u,%s,,%zu,%.4f,%.4f,%.4f,%.4f,%.4f,%.4f,%.4f,%.4f,%.4f,%.4f,%.4f,%.4f,%.1f,%.1f,%.1f,"
        "%.1f,%llu,%.1f,%.1f,%.1f,%.3f,%.3f,%llu,%d,%llu,%.2f,%.4f,%.1f,%.1f,%.3f\n",
        r.objects, modeName(r.mode), r.frames.size(), s.regionCountMs, s.regionScanMs,
        s.regionFillMs, s.regionMs, s.regionUsPerInstance, s.probeMs, s.probeP99Ms, s.costMs,
        base.probeMs > 0 ? s.costMs / base.probeMs : 0.0, s.traceMs, s.traceMs - base.traceMs,
        s.lightMs, s.pagesRelit, s.objectPagesRelit, s.probesUpdated, s.raysTraced,
        (unsigned long long)s.raysTracedTotal, s.objectRays, s.objectHits, s.objectSteps,
        s.stepsPerObjectRay, s.hostMs, (unsigned long long)r.nonFiniteTexels, r.irradianceChecks,
        (unsigned long long)r.validationMessages, r.wallSeconds, s.cardLightMs, s.cardRelit,
        s.cardStaleFrames, s.cardMiB);
    csv += row;
  }
  writeText(file, csv);
}

void writeFramesCsv(const fs::path& file, const std::vector<StressRun>& runs) {
  std::string csv =
      "objects,mode,frame,region_count_ms,region_scan_ms,region_fill_ms,probe_ms,probe_trace_ms,"
      "light_ms,pages_relit,object_pages_relit,probes_updated,rays_traced,rays_cached,"
      "object_rays,object_hits,object_steps,host_ms,motion_ms,scene_ms,objects_ms,"
      "shadow_pages_ms,light_host_ms,probes_host_ms,wall_ms\n";
  char row[640];
  for (const StressRun& r : runs)
    for (const StressFrame& f : r.frames) {
      std::snprintf(
          row, sizeof row,
          "%u,%s,%d,%.4f,%.4f,%.4f,%.4f,%.4f,%.4f,%u,%u,%u,%u,%u,%u,%u,%u,%.3f,%.3f,%.3f,%.3f,"
          "%.3f,%.3f,%.3f,%.3f\n",
          r.objects, modeName(r.mode), f.frame, f.regionCountMs, f.regionScanMs, f.regionFillMs,
          f.probeMs, f.traceMs, f.lightMs, f.pagesRelit, f.objectPagesRelit, f.probesUpdated,
          f.raysTraced, f.raysCached, f.objectRays, f.objectHits, f.objectSteps, f.hostMs(),
          f.motionMs, f.host.sceneMs, f.host.objectsMs, f.host.shadowPagesMs, f.host.lightMs,
          f.host.probesMs, f.wallMs);
      csv += row;
    }
  writeText(file, csv);
}

const glm::vec3 kRegionsColor{0.1f, 0.45f, 0.85f}, kNaiveColor{0.85f, 0.1f, 0.1f},
    kStaticColor{0.3f, 0.3f, 0.3f}, kGoalColor{0.1f, 0.6f, 0.2f};

// A measured curve over the object counts (> 0: the axis is logarithmic), as a line with markers.
void addCurve(Chart& chart, const std::vector<StressRun>& runs, Mode mode, const std::string& name,
              glm::vec3 color, const std::function<double(const RunSummary&)>& value) {
  Series line{name, {}, {}, color}, dots{"", {}, {}, color, true};
  for (const StressRun& r : runs)
    if (r.mode == mode && r.objects > 0 && measured(&r)) {
      line.x.push_back(r.objects), line.y.push_back(value(summarize(r)));
    }
  dots.x = line.x, dots.y = line.y;
  if (line.x.empty()) return;
  chart.series.push_back(std::move(line));
  chart.series.push_back(std::move(dots));
}

// A horizontal reference line across the plotted counts.
void addLevel(Chart& chart, const std::vector<std::uint32_t>& counts, const std::string& name,
              glm::vec3 color, double y) {
  double lo = 0.0, hi = 0.0;
  for (std::uint32_t c : counts)
    if (c > 0) lo = lo == 0.0 ? c : std::min(lo, double(c)), hi = std::max(hi, double(c));
  if (lo == 0.0) lo = 1.0, hi = 10.0;  // no object count to span: a decade
  if (hi <= lo) lo /= 2.0, hi *= 2.0;  // one count: a line across it
  chart.series.push_back(Series{name, {lo, hi}, {y, y}, color});
}

void writePlots(const fs::path& dir, const std::vector<StressRun>& runs) {
  const std::vector<std::uint32_t> counts = objectCounts(runs);
  const StressRun* st = findRun(runs, Mode::Static, 0);
  const RunSummary base = measured(st) ? summarize(*st) : RunSummary{};

  Chart cost{"Objects + probe update, GPU ms per frame (median)", "moving objects (log)", "ms", {}};
  cost.logX = true;
  addCurve(cost, runs, Mode::Regions, "regions: region build + probe update", kRegionsColor,
           [](const RunSummary& s) { return s.costMs; });
  addCurve(cost, runs, Mode::Naive, "naive: region build + probe update", kNaiveColor,
           [](const RunSummary& s) { return s.costMs; });
  if (measured(st)) {
    addLevel(cost, counts, "static-only probe update", kStaticColor, base.probeMs);
    addLevel(cost, counts, "goal: 2x static-only", kGoalColor, kGoalRatio * base.probeMs);
  }
  writeChartPng(dir / "probe-update.png", cost);

  Chart trace{"probe_trace pass, GPU ms per frame (median)", "moving objects (log)", "ms", {}};
  trace.logX = true;
  addCurve(trace, runs, Mode::Regions, "regions", kRegionsColor,
           [](const RunSummary& s) { return s.traceMs; });
  addCurve(trace, runs, Mode::Naive, "naive (every ray x every object)", kNaiveColor,
           [](const RunSummary& s) { return s.traceMs; });
  if (measured(st)) addLevel(trace, counts, "static-only", kStaticColor, base.traceMs);
  writeChartPng(dir / "probe-trace.png", trace);

  Chart regions{"Macro-region build (count + scan + fill), GPU ms per frame (median)",
                "moving objects (log)",
                "ms (log)",
                {}};
  regions.logX = regions.logY = true;
  addCurve(regions, runs, Mode::Regions, "region build", kRegionsColor,
           [](const RunSummary& s) { return s.regionMs; });
  // The line through the largest count's per-instance cost: what "proportional" looks like.
  Series linear{"proportional to objects", {}, {}, kStaticColor};
  for (const StressRun& r : runs)
    if (r.mode == Mode::Regions && r.objects > 0 && measured(&r)) linear.x.push_back(r.objects);
  if (!linear.x.empty()) {
    const StressRun* last = findRun(runs, Mode::Regions, std::uint32_t(linear.x.back()));
    const double perObject = summarize(*last).regionMs / linear.x.back();
    for (double x : linear.x) linear.y.push_back(perObject * x);
    regions.series.push_back(std::move(linear));
  }
  writeChartPng(dir / "region-build.png", regions);
}

// Per count: region build and traversal against static-only, both modes; then the growth from the
// smallest to the largest count as exponents (work ~ objects^e: e < 1 is sub-linear).
std::string scalingSection(const std::vector<StressRun>& runs) {
  const StressRun* st = findRun(runs, Mode::Static, 0);
  if (!measured(st)) return "";
  const RunSummary base = summarize(*st);
  std::string md =
      "\n## Scaling\n\nPer count in regions mode, against the static-only run: the region build "
      "(proportional to instances when the time per instance stays flat), the traversal cost (the "
      "probe_trace pass minus static-only's) and the object sphere-tracing steps per frame "
      "(means), in "
      "both modes. Objects are spread evenly over the same area at every count, so the density a "
      "ray meets grows with the count; the regions walk only meets the objects listed along the "
      "ray and only up to the static hit. Object steps count sphere-tracing steps inside the "
      "boxes a ray enters; the naive walk's box test of every instance against every ray is not "
      "a step, and is where its extra time goes.\n\n"
      "| objects | region build ms | us / instance | traversal ms, regions | traversal ms, naive | "
      "object steps / frame, regions | object steps / frame, naive | steps / object ray, "
      "regions |\n|---|---|---|---|---|---|---|---|\n";
  std::vector<std::uint32_t> counts = objectCounts(runs);
  // Per frame, means rather than medians: at small counts most frames' rays enter no object box.
  auto meanSteps = [](const StressRun& r) {
    return double(summarize(r).objectStepsTotal) /
           double(std::max<std::size_t>(1, r.frames.size()));
  };
  struct Point {
    double n, traversal, steps, naiveSteps;  // naiveSteps < 0: no naive run
  };
  std::vector<Point> points;
  for (std::uint32_t n : counts) {
    if (n == 0) continue;
    const StressRun* r = findRun(runs, Mode::Regions, n);
    const StressRun* nv = findRun(runs, Mode::Naive, n);
    if (!measured(r)) continue;
    const RunSummary s = summarize(*r);
    const std::string naiveTrace =
        measured(nv) ? format("%.3f", summarize(*nv).traceMs - base.traceMs) : "skipped";
    const std::string naiveSteps = measured(nv) ? format("%.0f", meanSteps(*nv)) : "skipped";
    md += "| " + withCommas(n) + " | " + format("%.3f", s.regionMs) + " | " +
          format("%.3f", s.regionUsPerInstance) + " | " + format("%.3f", s.traceMs - base.traceMs) +
          " | " + naiveTrace + " | " + format("%.0f", meanSteps(*r)) + " | " + naiveSteps + " | " +
          format("%.1f", s.stepsPerObjectRay) + " |\n";
    points.push_back(
        {double(n), s.traceMs - base.traceMs, meanSteps(*r), measured(nv) ? meanSteps(*nv) : -1.0});
  }
  auto exponent = [](double from, double to, double k) {
    return from > 0 && to > 0 ? format("%.2f", std::log(to / from) / std::log(k)) : "n/a";
  };
  if (points.size() >= 2) {
    const Point& a = points.front();
    const Point& b = points.back();
    const double k = b.n / a.n;
    md += "\nFrom " + withCommas(std::uint64_t(a.n)) + " to " + withCommas(std::uint64_t(b.n)) +
          " objects (x" + format("%.0f", k) +
          "), as exponents e of work ~ objects^e (1 = linear):" +
          " object steps per frame, regions " + exponent(a.steps, b.steps, k);
    if (a.naiveSteps >= 0 && b.naiveSteps >= 0)
      md += ", naive " + exponent(a.naiveSteps, b.naiveSteps, k);
    md += "; traversal time, regions " + exponent(a.traversal, b.traversal, k);
    if (!(a.traversal > 0 && b.traversal > 0))
      md += " (not above static-only's at one end: " + format("%+.3f", a.traversal) + " and " +
            format("%+.3f", b.traversal) + " ms)";
    md += ".";
    if (b.naiveSteps > 0 && b.steps > 0)
      md += " At " + withCommas(std::uint64_t(b.n)) + " objects the naive walk takes " +
            format("%.1f", b.naiveSteps / b.steps) + "x the regions walk's object steps.";
    md += "\n";
  }
  return md;
}

// Every target of the benchmark in one table: measured against the goal, yes or no.
std::string goalsSection(const std::vector<StressRun>& runs) {
  const StressRun* st = findRun(runs, Mode::Static, 0);
  if (!measured(st)) return "";
  const RunSummary base = summarize(*st);
  if (!(base.probeMs > 0.0)) return "";
  std::string md = "\n## Goals\n\n| target | goal | measured | met |\n|---|---|---|---|\n";
  auto row = [&](const std::string& what, const std::string& goal, double value, bool met) {
    md += "| " + what + " | " + goal + " | " + format("%.2f", value) + " | " +
          (met ? "yes" : "**no**") + " |\n";
  };
  for (const auto& [objects, ratio] : kCountGoals) {
    const StressRun* r = findRun(runs, Mode::Regions, objects);
    if (!measured(r)) continue;
    const RunSummary s = summarize(*r);
    row(withCommas(objects) + " objects: regions + probe update / static-only",
        format("<= %.1fx", ratio), s.costMs / base.probeMs, s.costMs / base.probeMs <= ratio);
  }
  if (const StressRun* g = findRun(runs, Mode::Regions, kGoalObjects); measured(g)) {
    const RunSummary s = summarize(*g);
    const double light = (s.costMs + s.lightMs) / (base.probeMs + base.lightMs);
    row(withCommas(kGoalObjects) + " objects: with the light cache / static-only's",
        format("<= %.1fx", kGoalLightRatio), light, light <= kGoalLightRatio);
    row(withCommas(kGoalObjects) + " objects: host ms per frame", format("<= %.1f", kGoalHostMs),
        s.hostMs, s.hostMs <= kGoalHostMs);
  }
  return md;
}

// Host time per frame by part (regions mode, and the static-only baseline), and how it and the
// GPU cost grow with the object count.
std::string hostSection(const std::vector<StressRun>& runs) {
  std::string md =
      "\n## Host time\n\nCPU milliseconds per frame (medians): the scripted motion, then "
      "GiSystem's recording of the frame by part -- scene (page tables, streamed bricks), objects "
      "(instances into stack space, region state, uploads; build: without the uploads, by part: "
      "instances / changed boxes and wake bits / card light blocks, the first two side by side), "
      "shadow pages (light-cache pages the moves shadow, found on a worker thread during "
      "*objects*: its own time, overlapping that one), light (dirty pages, the light cache pass), "
      "probes (the probe passes). Each part is its own time, so they do not add up to *host* = "
      "motion + recording (wall time); *wall* adds the blocking update's submit and its wait for "
      "the GPU.\n\n"
      "| objects | mode | host ms | motion | scene | objects (build: instances / wake / cards) | "
      "shadow pages | light | "
      "probes | wall ms | host us / instance |\n|---|---|---|---|---|---|---|---|---|---|---|\n";
  struct Point {
    double n, host, cost;
  };
  std::vector<Point> points;
  for (const StressRun& r : runs) {
    if (!r.skipped.empty() || r.frames.empty() || r.mode == Mode::Naive) continue;
    const RunSummary s = summarize(r);
    md += "| " + (hasObjects(r.mode) ? withCommas(r.objects) : std::string("-")) + " | " +
          modeName(r.mode) + " | " + format("%.3f", s.hostMs) + " | " + format("%.3f", s.motionMs) +
          " | " + format("%.3f", s.host.sceneMs) + " | " + format("%.3f", s.host.objectsMs) + " (" +
          format("%.3f", s.host.objectsBuildMs) + ": " + format("%.3f", s.host.objectsInstancesMs) +
          " / " + format("%.3f", s.host.objectsWakeMs) + " / " +
          format("%.3f", s.host.objectsCardsMs) + ") | " + format("%.3f", s.host.shadowPagesMs) +
          " | " + format("%.3f", s.host.lightMs) + " | " + format("%.3f", s.host.probesMs) + " | " +
          format("%.3f", s.wallMs) + " | " +
          (r.objects ? format("%.3f", 1000.0 * s.hostMs / r.objects) : std::string("-")) + " |\n";
    if (r.mode == Mode::Regions && r.objects > 0)
      points.push_back({double(r.objects), s.hostMs, s.costMs + s.lightMs});
  }
  if (points.size() >= 2) {
    md +=
        "\nScaling exponents e of time ~ objects^e between successive counts (1 = linear), "
        "host time and GPU time (regions + probe update + light cache):\n\n"
        "| from | to | host e | GPU e |\n|---|---|---|---|\n";
    for (std::size_t i = 1; i < points.size(); ++i) {
      const Point& a = points[i - 1];
      const Point& b = points[i];
      const double k = std::log(b.n / a.n);
      auto e = [&](double x, double y) {
        return x > 0 && y > 0 ? format("%.2f", std::log(y / x) / k) : std::string("n/a");
      };
      md += "| " + withCommas(std::uint64_t(a.n)) + " | " + withCommas(std::uint64_t(b.n)) + " | " +
            e(a.host, b.host) + " | " + e(a.cost, b.cost) + " |\n";
    }
  }
  return md;
}

}  // namespace

const char* modeName(Mode mode) {
  switch (mode) {
    case Mode::Static:
      return "static";
    case Mode::StaticRepeat:
      return "static-repeat";
    case Mode::Regions:
      return "regions";
    case Mode::Naive:
      return "naive";
    case Mode::RegionsNoCards:
      return "regions-no-cards";
  }
  return "?";
}

RunSummary summarize(const StressRun& run) {
  RunSummary s;
  if (run.frames.empty()) return s;
  s.regionCountMs = medianOf(run, [](const StressFrame& f) { return f.regionCountMs; });
  s.regionScanMs = medianOf(run, [](const StressFrame& f) { return f.regionScanMs; });
  s.regionFillMs = medianOf(run, [](const StressFrame& f) { return f.regionFillMs; });
  s.regionMs = medianOf(run, [](const StressFrame& f) { return f.regionMs(); });
  s.regionUsPerInstance = run.objects ? s.regionMs * 1000.0 / run.objects : 0.0;
  s.probeMs = medianOf(run, [](const StressFrame& f) { return f.probeMs; });
  std::vector<double> probe;
  for (const StressFrame& f : run.frames) probe.push_back(f.probeMs);
  s.probeP99Ms = percentile(probe, 0.99);
  s.traceMs = medianOf(run, [](const StressFrame& f) { return f.traceMs; });
  s.lightMs = medianOf(run, [](const StressFrame& f) { return f.lightMs; });
  s.costMs = medianOf(run, [](const StressFrame& f) { return f.costMs(); });
  s.hostMs = medianOf(run, [](const StressFrame& f) { return f.hostMs(); });
  s.motionMs = medianOf(run, [](const StressFrame& f) { return f.motionMs; });
  const auto hostPart = [&](double GiHostTimes::*part) {
    return medianOf(run, [part](const StressFrame& f) { return f.host.*part; });
  };
  for (double GiHostTimes::*part :
       {&GiHostTimes::sceneMs, &GiHostTimes::objectsMs, &GiHostTimes::objectsBuildMs,
        &GiHostTimes::objectsInstancesMs, &GiHostTimes::objectsWakeMs, &GiHostTimes::objectsCardsMs,
        &GiHostTimes::shadowPagesMs, &GiHostTimes::lightMs, &GiHostTimes::probesMs,
        &GiHostTimes::totalMs})
    s.host.*part = hostPart(part);
  s.wallMs = medianOf(run, [](const StressFrame& f) { return f.wallMs; });
  s.pagesRelit = medianOf(run, [](const StressFrame& f) { return f.pagesRelit; });
  s.objectPagesRelit = medianOf(run, [](const StressFrame& f) { return f.objectPagesRelit; });
  s.probesUpdated = medianOf(run, [](const StressFrame& f) { return f.probesUpdated; });
  s.raysTraced = medianOf(run, [](const StressFrame& f) { return f.raysTraced; });
  s.objectRays = medianOf(run, [](const StressFrame& f) { return f.objectRays; });
  s.objectHits = medianOf(run, [](const StressFrame& f) { return f.objectHits; });
  s.objectSteps = medianOf(run, [](const StressFrame& f) { return f.objectSteps; });
  for (const StressFrame& f : run.frames) {
    s.raysTracedTotal += f.raysTraced;
    s.objectRaysTotal += f.objectRays;
    s.objectStepsTotal += f.objectSteps;
  }
  s.stepsPerObjectRay =
      s.objectRaysTotal ? double(s.objectStepsTotal) / double(s.objectRaysTotal) : 0.0;
  s.cardLightMs = medianOf(run, [](const StressFrame& f) { return f.cardLightMs; });
  s.cardRelit = medianOf(run, [](const StressFrame& f) { return f.cardRelit; });
  s.cardStaleFrames = medianOf(run, [](const StressFrame& f) { return double(f.cardStaleFrames); });
  s.cardMiB = medianOf(run, [](const StressFrame& f) { return f.cardMiB; });
  return s;
}

StressChecks checkRuns(const std::vector<StressRun>& runs) {
  StressChecks c;
  for (const StressRun& r : runs) {
    c.nonFiniteTexels += r.nonFiniteTexels;
    c.nonFiniteCardTexels += r.nonFiniteCardTexels;
    c.validationMessages += r.validationMessages;
  }
  const StressRun* st = findRun(runs, Mode::Static, 0);
  const StressRun* zero = findRun(runs, Mode::Regions, 0);
  const std::string goal = "Goal (" + withCommas(kGoalObjects) +
                           " spread objects cost <= 2x the static-only probe update): ";
  if (!measured(st)) {
    c.goalLine = goal + "not measured (no static-only run).";
    c.zeroLine = "0 objects vs static-only: not measured (no static-only run).";
    return c;
  }
  const RunSummary base = summarize(*st);
  if (!(base.probeMs > 0.0)) {  // no GPU timestamps on this queue: every time reads 0
    c.goalLine = goal + "not measurable (the device reports no GPU timestamps).";
  }
  const StressRun* g = findRun(runs, Mode::Regions, kGoalObjects);
  if (!c.goalLine.empty()) {
    // said above
  } else if (measured(g)) {
    const RunSummary s = summarize(*g);
    const double ratio = s.costMs / base.probeMs;
    c.goalLine = goal + (ratio <= kGoalRatio ? "**yes**" : "**no**") + " -- region build " +
                 format("%.3f", s.regionMs) + " ms + probe update " + format("%.3f", s.probeMs) +
                 " ms = " + format("%.3f", s.costMs) + " ms, " + format("%.2f", ratio) +
                 "x the static-only probe update of " + format("%.3f", base.probeMs) +
                 " ms (medians per frame). With the light cache, which relights the pages the "
                 "moving objects shadow or unshadow (" +
                 format("%.3f", s.lightMs) + " ms), the GI frame costs " +
                 format("%.3f", s.costMs + s.lightMs) + " ms, " +
                 format("%.2f", (s.costMs + s.lightMs) / (base.probeMs + base.lightMs)) +
                 "x static-only's " + format("%.3f", base.probeMs + base.lightMs) + " ms.";
  } else {
    std::uint32_t largest = 0;
    for (const StressRun& r : runs)
      if (r.mode == Mode::Regions && measured(&r)) largest = std::max(largest, r.objects);
    const StressRun* l = findRun(runs, Mode::Regions, largest);
    c.goalLine =
        goal + "not measured in this run (no " + withCommas(kGoalObjects) + "-object count)";
    if (largest > 0 && measured(l)) {
      const RunSummary s = summarize(*l);
      c.goalLine += "; at the largest count, " + withCommas(largest) + " objects, region build + " +
                    "probe update = " + format("%.3f", s.costMs) + " ms, " +
                    format("%.2f", s.costMs / base.probeMs) + "x static-only's " +
                    format("%.3f", base.probeMs) + " ms";
    }
    c.goalLine += ".";
  }
  if (measured(zero)) {
    const StressRun* again = findRun(runs, Mode::StaticRepeat, 0);
    // Frames with equal rays traced and probes updated, and the relative difference of the totals.
    auto compare = [&](const StressRun& a, std::size_t* equal) {
      *equal = 0;
      for (std::size_t i = 0; i < std::min(a.frames.size(), st->frames.size()); ++i)
        *equal += a.frames[i].raysTraced == st->frames[i].raysTraced &&
                  a.frames[i].probesUpdated == st->frames[i].probesUpdated;
      return 100.0 * (double(summarize(a).raysTracedTotal) / double(base.raysTracedTotal) - 1.0);
    };
    for (const StressFrame& f : zero->frames)
      c.zeroObjectsNoObjectWork = c.zeroObjectsNoObjectWork && f.regionMs() == 0.0 &&
                                  f.objectRays == 0 && f.objectSteps == 0 && f.objectHits == 0;
    std::size_t equal = 0;
    const double delta = base.raysTracedTotal ? compare(*zero, &equal) : 0.0;
    const std::size_t n = st->frames.size();
    c.zeroObjectsSameRays = zero->frames.size() == n && equal == n;
    const RunSummary z = summarize(*zero);
    c.zeroLine = std::string("0 objects vs static-only: no object work: ") +
                 (c.zeroObjectsNoObjectWork ? "**yes**" : "**NO**") +
                 " (region passes dispatched: " + (z.regionMs > 0 ? "some" : "none") +
                 "; probe rays that searched objects: " + withCommas(z.objectRaysTotal) +
                 "). Same rays traced and probes updated as static-only: ";
    if (c.zeroObjectsSameRays)
      c.zeroLine += "**identical in all " + std::to_string(n) + " frames** (" +
                    withCommas(z.raysTracedTotal) + " rays).";
    else
      c.zeroLine += "in " + std::to_string(equal) + " of " + std::to_string(n) + " frames (" +
                    withCommas(z.raysTracedTotal) + " vs " + withCommas(base.raysTracedTotal) +
                    " rays in all, " + format("%+.3f", delta) + "%).";
    if (measured(again)) {
      std::size_t equalAgain = 0;
      const double deltaAgain = base.raysTracedTotal ? compare(*again, &equalAgain) : 0.0;
      const RunSummary r = summarize(*again);
      c.zeroLine += " The static-only run repeated: equal in " + std::to_string(equalAgain) +
                    " of " + std::to_string(n) + " frames (" + format("%+.3f", deltaAgain) +
                    "% rays)" +
                    (equalAgain < n ? ": the probe selection at the ray budget's cutoff depends "
                                      "on thread order, so runs of the same work can differ"
                                    : "") +
                    ". Probe update, medians: static-only " + format("%.3f", base.probeMs) +
                    " ms, repeated " + format("%.3f", r.probeMs) + " ms (" +
                    format("%+.1f", 100.0 * (r.probeMs / base.probeMs - 1.0)) +
                    "%: the timing noise), 0 objects " + format("%.3f", z.probeMs) + " ms (" +
                    format("%+.1f", 100.0 * (z.probeMs / base.probeMs - 1.0)) + "%).";
    } else {
      c.zeroLine += " Probe update, medians: " + format("%.3f", z.probeMs) + " vs " +
                    format("%.3f", base.probeMs) + " ms (" +
                    format("%+.1f", 100.0 * (z.probeMs / base.probeMs - 1.0)) + "%).";
    }
  } else {
    c.zeroLine =
        "0 objects vs static-only: not measured (no 0-object run; 0 is in the default --objects).";
  }
  return c;
}

std::string stressTable(const std::vector<StressRun>& runs) {
  const StressRun* st = findRun(runs, Mode::Static, 0);
  const RunSummary base = measured(st) ? summarize(*st) : RunSummary{};
  std::string md =
      "| objects | mode | regions + probe ms | x static | region build ms (count/scan/fill) | "
      "us / instance | probe update ms (p99) | probe_trace ms | trace - static ms | light ms | "
      "pages relit (by objects) | rays traced | object rays | object hits | steps / object ray | "
      "host ms | non-finite texels | validation msgs |\n"
      "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n";
  for (const StressRun& r : runs) {
    const std::string objects = hasObjects(r.mode) ? withCommas(r.objects) : "-";
    if (!r.skipped.empty()) {
      md += "| " + objects + " | " + modeName(r.mode) + " | skipped: " + r.skipped +
            " | | | | | | | | | | | | | | | |\n";
      continue;
    }
    const RunSummary s = summarize(r);
    char row[1024];
    std::snprintf(
        row, sizeof row,
        "| %s | %s | %.3f | %.2f | %.3f (%.3f/%.3f/%.3f) | %.3f | %.3f (%.3f) | %.3f | %+.3f | "
        "%.3f | %.0f (%.0f) | %.0f | %.0f | %.0f | %.1f | %.1f | %llu | %llu |\n",
        objects.c_str(), modeName(r.mode), s.costMs,
        base.probeMs > 0 ? s.costMs / base.probeMs : 0.0, s.regionMs, s.regionCountMs,
        s.regionScanMs, s.regionFillMs, s.regionUsPerInstance, s.probeMs, s.probeP99Ms, s.traceMs,
        s.traceMs - base.traceMs, s.lightMs, s.pagesRelit, s.objectPagesRelit, s.raysTraced,
        s.objectRays, s.objectHits, s.stepsPerObjectRay, s.hostMs,
        (unsigned long long)r.nonFiniteTexels, (unsigned long long)r.validationMessages);
    md += row;
  }
  return md;
}

// Cards on vs off per count: what the card light costs and holds, and what it changes.
std::string cardsSection(const std::vector<StressRun>& runs) {
  std::string md =
      "\n## Cards\n\nPer object count, the regions run (cards on) against the same run with "
      "the cards off (regions-no-cards). *card light ms*: the light_cache_cards pass (part of "
      "the light cache); *relit*: instances whose card light it recomputed (median per frame); "
      "*stale*: frames since the longest-unlit instance's last relight (median); *MiB*: card "
      "atlas + card light on the device; *capture*: the first frame's capture of every mesh's "
      "cards (GPU ms, and per mesh).\n\n"
      "| objects | regions + probe, cards on | cards off | card light ms | relit | stale | MiB | "
      "capture ms (meshes; per mesh) |\n"
      "|---|---|---|---|---|---|---|---|\n";
  char row[512];
  bool any = false;
  for (const StressRun& r : runs) {
    if (r.mode != Mode::Regions || r.objects == 0 || !measured(&r)) continue;
    const RunSummary on = summarize(r);
    const StressRun* off = findRun(runs, Mode::RegionsNoCards, r.objects);
    const std::string offText = measured(off) ? format("%.3f", summarize(*off).costMs) : "skipped";
    std::snprintf(row, sizeof row,
                  "| %s | %.3f | %s | %.4f | %.0f | %.0f | %.2f | %.3f (%u; %.4f) |\n",
                  withCommas(r.objects).c_str(), on.costMs, offText.c_str(), on.cardLightMs,
                  on.cardRelit, on.cardStaleFrames, on.cardMiB, r.captureMs, r.meshesCaptured,
                  r.meshesCaptured > 0 ? r.captureMs / double(r.meshesCaptured) : 0.0);
    md += row;
    any = true;
  }
  return any ? md : std::string();
}

void writeStressReport(const fs::path& dir, const StressSetup& setup,
                       const std::vector<StressRun>& runs, const StressChecks& checks) {
  writeResultsCsv(dir / "results.csv", runs);
  writeFramesCsv(dir / "frames.csv", runs);
  writePlots(dir, runs);

  int downloads = 0;
  for (const StressRun& r : runs) downloads += r.irradianceChecks;
  std::string md = "# Moving-object stress test\n\n";
  md += "- World: `" + setup.world + "`\n- Device: " + setup.device +
        (setup.software ? " (a CPU Vulkan implementation: times are not a GPU's, and the probe "
                          "ray budget is cut to keep the run short)"
                        : "") +
        "\n- Command: `" + setup.command + "`\n";
  char text[1024];
  std::snprintf(
      text, sizeof text,
      "- GI: default settings; %d cascades (cascade-0 voxel %.3g m), macro regions in the "
      "first %d; %u rays per probe, at most %u probe rays per frame\n"
      "- Frames: %d measured per run after %d warm-up frames; every run starts from a "
      "fresh GiSystem on the same settled stack, camera fixed\n",
      setup.cascades, setup.voxel0, setup.regionCascades, setup.raysPerProbe, setup.probeBudget,
      setup.frames, setup.warmup);
  md += text;
  md += "- Camera: " + setup.camera + "\n- Objects: " + setup.area +
        "; unit boxes and spheres (spreadObjects, seed " + std::to_string(setup.seed) +
        "), 0.3-2 m, each orbiting, falling or driving a loop (ScriptedMotion applied every frame, "
        "t = frame / 60 s); the same instances and motion in regions and naive mode\n";
  md +=
      "- Modes: **static** = no object scene at all (`setObjects(nullptr)`), the baseline, and "
      "**static-repeat** the same again (after the 0-object run), the noise floor; "
      "**regions** = probe rays search the objects through the macro-region lists, only up to "
      "the static hit; **naive** = every probe ray tests every instance (the region lists are "
      "still built, so their cost is in both)\n";

  if (int(runs.size()) < setup.runsPlanned)
    md += "\n**Partial:** " + std::to_string(runs.size()) + " of " +
          std::to_string(setup.runsPlanned) +
          " runs done when this was written (it is rewritten after each run).\n";
  md += "\n## Checks\n\n";
  md += std::string("- Non-finite probe irradiance texels: ") +
        (checks.nonFiniteTexels == 0 ? "**none**"
                                     : "**" + std::to_string(checks.nonFiniteTexels) + "**") +
        " over " + std::to_string(downloads) +
        " downloads of every probe's irradiance (every 100 measured frames and at the end of each "
        "run)\n";
  md +=
      std::string(
          "- Card light texels whose radiance came out NaN or infinite (counted by the "
          "card light pass, every relight of every run): ") +
      (checks.nonFiniteCardTexels == 0 ? "**none**"
                                       : "**" + std::to_string(checks.nonFiniteCardTexels) + "**") +
      "\n";
  md += setup.validation
            ? "- Vulkan validation messages: **" + std::to_string(checks.validationMessages) +
                  "** (Khronos validation layer on)\n"
            : std::string(
                  "- Vulkan validation messages: not checked (validation layer off; run "
                  "with --validation)\n");
  md += "- " + checks.zeroLine + "\n- " + checks.goalLine + "\n";
  md += std::string("- Result: ") + (checks.passed() ? "passed" : "**FAILED**") +
        " (no NaN, no validation message, no object work with 0 objects)\n";

  md +=
      "\n## Per object count and mode\n\nGPU milliseconds per frame, medians over the measured "
      "frames (frames.csv has every frame). *regions + probe* = the region passes + every probe "
      "pass, the frame's cost of the objects and the probe update together; *x static* divides "
      "it by the static-only probe update. *trace - static* = this run's probe_trace pass minus "
      "static-only's: the traversal cost of the objects. *pages relit (by objects)*: light-cache "
      "pages relit, and of those the ones objects' moves shadowed or unshadowed. *host ms*: CPU "
      "time of the scripted motion and of recording the GI frame (no waits; by part under Host "
      "time).\n\n";
  md += stressTable(runs);
  md += goalsSection(runs);
  md += scalingSection(runs);
  md += hostSection(runs);
  md += cardsSection(runs);
  md +=
      "\nNaive mode tests every probe ray against every instance over the ray's whole "
      "length: also beyond the cascades that have region lists, where the regions walk sees no "
      "objects, and, for a coarse cascade's probe, objects its size rule leaves out of that "
      "cascade's lists. So its object hits can exceed the regions mode's.\n";
  md +=
      "\n## Plots\n\n![objects + probe update vs object count](probe-update.png)\n\n"
      "![probe_trace vs object count](probe-trace.png)\n\n"
      "![region build vs object count](region-build.png)\n";
  writeText(dir / "summary.md", md);
}

}  // namespace sdfstream::bench::stress
