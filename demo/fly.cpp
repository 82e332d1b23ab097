#include "demo/fly.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "core/atomic_dir.h"
#include "core/error.h"
#include "core/stopwatch.h"
#include "demo/fly_path.h"
#include "demo/fly_report.h"
#include "demo/frame_image.h"
#include "demo/gi_shading.h"
#include "demo/moving_objects.h"
#include "demo/streamed_gi.h"
#include "demo/time_of_day.h"
#include "gi/camera.h"
#include "gpu/context.h"
#include "streaming/cascade_stack.h"
#include "streaming/pack_store.h"
#include "streaming/stream_metrics.h"

namespace fs = std::filesystem;

namespace sdfstream {
namespace {

using Clock = std::chrono::steady_clock;

// Exposure added to the indirect-only layer of --layers (stops).
constexpr float kIndirectLayerStops = 2.0f;

// Resident set size of this process (VmRSS of /proc/self/status), 0 where unavailable.
std::uint64_t residentBytes() {
  std::ifstream status("/proc/self/status");
  std::string line;
  while (std::getline(status, line))
    if (line.rfind("VmRSS:", 0) == 0) return std::strtoull(line.c_str() + 6, nullptr, 10) * 1024;
  return 0;
}

// Distance along a path of `length` at travelled distance `s`, back and forth.
double pingPong(double s, double length) {
  if (length <= 0.0) return 0.0;
  const double period = std::fmod(s, 2.0 * length);
  return period <= length ? period : 2.0 * length - period;
}

// One sample of a long run's memory (FlyOptions::loop runs report start, peak and end).
struct MemorySample {
  int frame = 0;
  std::uint64_t rss = 0, gpuBuffers = 0;
};

StreamedGiOptions streamedOptions(const FlyOptions& o) {
  StreamedGiOptions so;
  so.world = o.world;
  so.cascades = o.cascades;
  so.atlasMiB = o.atlasMiB;
  so.uploadMiB = o.uploadMiB;
  so.loaderThreads = o.loaderThreads;
  so.render = o.render;
  return so;
}

// One fly-through, set up by the constructor (pack, path, device, stack, renderer, objects) and
// run in steps: warmUp, fly (every frame), writeOutputs.
class FlyThrough {
 public:
  explicit FlyThrough(const FlyOptions& o)
      : o_(o),
        context_(o.device ? gpu::Context::create(*o.device) : nullptr),
        world_(streamedOptions(o), context_.get()),
        path_(o.path ? readFlyPath(*o.path)
                     : defaultFlyPath(world_.store().manifest().boundsMin,
                                      world_.store().manifest().boundsMax)),
        length_(path_.length()),
        sweepBase_(world_.render().lights) {
    if (world_.renderer() && o.objects > 0) placeObjects();
    fs::create_directories(o.out / "frames");
  }

  void printStart() const {
    std::printf(
        "fly: %s, %d frames along %.0f m at %.1f m/s, %d cascades, atlas %.0f MiB, GI %s "
        "(%u probe rays per frame), %zu moving objects%s, on %s\n",
        o_.world.c_str(), o_.frames, length_, o_.speed, world_.stack().cascadeCount(),
        double(world_.stack().atlasBytes()) / (1 << 20), world_.render().gi ? "on" : "off",
        world_.render().renderer.settings.probes.rayBudget,
        world_.objects() ? world_.objects()->instances.size() : 0, sweepNote().c_str(),
        context_ ? context_->deviceName().c_str() : "CPU reference");
  }

  std::string sweepNote() const {
    if (!o_.sunSweep) return "";
    char text[96];
    std::snprintf(text, sizeof text, ", sun from %.0f to %.0f degrees elevation", o_.sunSweep->x,
                  o_.sunSweep->y);
    return text;
  }

  // GI frames at the start of the path, streaming too; their loader stats stay out of the
  // metrics.
  void warmUp() {
    for (int w = 0; w < o_.warmupGiFrames; ++w) {
      const Camera cam = cameraAt(0.0);
      if (world_.objects()) world_.objects()->apply(0.0);
      world_.stream(cam);
      world_.giUpdate(cam);
    }
    if (o_.warmupGiFrames > 0) world_.loader().takeStats();
  }

  // Frames are paced at 30 per wall-clock second (unless pacing is off) so the loader threads get
  // the same real time per frame as they would in an interactive application.
  void fly() {
    const auto start = Clock::now();
    for (int f = 0; f < o_.frames; ++f) {
      const double seconds = f / 30.0;
      if (o_.pacing)
        std::this_thread::sleep_until(start +
                                      std::chrono::microseconds(std::int64_t(seconds * 1e6)));
      frame(f, seconds);
      if (f % std::max(1, o_.frames / 100) == 0 || f == o_.frames - 1)
        memory_.push_back({f, residentBytes(), context_ ? context_->liveBufferBytes() : 0});
      if (f % std::max(1, o_.frames / 10) == 0 || f == o_.frames - 1)
        std::fprintf(stderr,
                     "  frame %d/%d: %u missing pages, %zu tiles cached, RSS %.1f MiB, GPU "
                     "buffers %.1f MiB\n",
                     f + 1, o_.frames, lastStream_.missingPages, lastCachedTiles_,
                     double(memory_.back().rss) / (1 << 20),
                     double(memory_.back().gpuBuffers) / (1 << 20));
    }
  }

  // metrics.csv, gi.csv, summary.md and the charts; 1 when tiles failed to load.
  int writeOutputs() const {
    writeMetricsCsv(o_.out / "metrics.csv", metrics_);
    const MetricsSummary summary = summarize(metrics_);
    writeGiCsv(o_.out / "gi.csv", giMetrics_);
    const bool gi = world_.renderer() && world_.renderer()->giEnabled();
    const std::string giMd =
        giSummaryMarkdown(giMetrics_, gi, world_.render().renderer.settings.probes,
                          world_.renderer() ? world_.renderer()->probeDeviceBytes() : 0) +
        relightSummaryMarkdown(giMetrics_, gi,
                               world_.render().renderer.settings.light.relightPageBudget) +
        objectSummaryMarkdown(giMetrics_, gi);
    std::string md = "# Fly-through summary\n\nWorld: " + o_.world.string() +
                     (o_.sunSweep ? "\n\nDay-to-dusk sweep" + sweepNote() : std::string()) +
                     "\n\n" + summaryMarkdown(summary) + giMd + memoryMarkdown();
    const auto failed = world_.loader().failedTiles();
    if (!failed.empty()) {
      md += "\nTiles that failed to load (reported, never treated as empty):\n";
      for (const TileKey& k : failed)
        md += "- tile " + std::to_string(k.coord.x) + "_" + std::to_string(k.coord.y) + "_" +
              std::to_string(k.coord.z) + " LOD " + std::to_string(k.lod) + "\n";
    }
    writeFileAtomically(o_.out / "summary.md", md.data(), md.size());
    writeFlyPlots(o_.out, metrics_);
    std::printf(
        "fly: wrote %s (metrics.csv, gi.csv, summary.md, residency.png, bytes.png, "
        "frames/)\n%s%s",
        o_.out.c_str(), summaryMarkdown(summary).c_str(), giMd.c_str());
    return failed.empty() ? 0 : 1;
  }

 private:
  // The objects spread over the stretch the camera flies, from a little ahead of its start to
  // a little beyond its end (the camera looks ahead and down), on the pack's ground.
  void placeObjects() {
    const PackManifest& manifest = world_.store().manifest();
    PackGround ground(world_.store(), manifest.boundsMin.y, manifest.boundsMax.y);
    FlyObjectsSettings os;
    os.count = o_.objects;
    os.sBegin = std::min(15.0, length_);
    os.sEnd = std::min(length_, o_.speed * (o_.frames - 1) / 30.0 + 90.0);
    world_.setObjects(flyObjects(ground, path_, os));
  }

  Camera cameraAt(double s) const { return pathCamera(path_, s); }

  // Moves the suns to this frame's elevation of the sweep (a light change every frame: the light
  // cache relights within its page budget, the longest out of date first).
  void sweepSun(int f) {
    const double t = o_.frames > 1 ? double(f) / (o_.frames - 1) : 1.0;
    const double elevation = glm::mix(o_.sunSweep->x, o_.sunSweep->y, t);
    SceneLights next = daylightAt(sweepBase_, elevation);
    next.version = world_.render().lights.version + 1;
    world_.render().lights = std::move(next);
  }

  // Stream, move the objects, update the GI, and render when this frame is written.
  void frame(int f, double seconds) {
    const double travelled = o_.speed * seconds;
    const Camera cam = cameraAt(o_.loop ? pingPong(travelled, length_) : travelled);
    if (o_.sunDegreesPerFrame != 0.0) world_.turnSuns(o_.sunDegreesPerFrame);
    if (o_.sunSweep) sweepSun(f);
    FrameMetrics m;
    m.frame = f;
    m.seconds = seconds;
    m.camera = cam.position;
    const auto t0 = Clock::now();
    m.stream = world_.stream(cam);
    m.updateMilliseconds = millisecondsSince(t0);
    GiFrameMetrics g;
    g.frame = f;
    if (world_.objects())
      world_.objects()->apply(seconds);  // the GI update below consumes the moves
    world_.withinDeviceMemory(f, [&] {
      g.gi = world_.giUpdate(cam);
      if (world_.renderer()) g.probePasses = world_.renderer()->lastTimes().probePasses;
      m.gpuBytes = world_.stack().atlasBytes() +
                   std::size_t(world_.stack().cascadeCount()) * layout::kCascadePageCount * 4;
      if (f % o_.imageEvery == 0 || f == o_.frames - 1) render(f, cam, m, g);
    });
    m.loader = world_.loader().takeStats();
    lastStream_ = m.stream;
    lastCachedTiles_ = m.loader.cachedTiles;
    if (f % std::max(1, o_.metricsEvery) == 0 || f == o_.frames - 1) {
      giMetrics_.push_back(std::move(g));
      metrics_.push_back(std::move(m));
    }
  }

  // Start (after the first tenth of the run), peak and end of the process's RSS and of the live
  // GPU buffers, and the rendered pixels that were not finite.
  std::string memoryMarkdown() const {
    if (memory_.empty()) return "";
    const std::size_t settled = memory_.size() / 10;
    MemorySample start = memory_[std::min(settled, memory_.size() - 1)], peak{},
                 end = memory_.back();
    for (const MemorySample& m : memory_) {
      peak.rss = std::max(peak.rss, m.rss);
      peak.gpuBuffers = std::max(peak.gpuBuffers, m.gpuBuffers);
    }
    auto mib = [](std::uint64_t b) { return double(b) / double(1 << 20); };
    char text[1024];
    std::snprintf(text, sizeof text,
                  "\n## Memory over the run\n\n| | start (frame %d) | peak | end (frame %d) |\n"
                  "|---|---|---|---|\n| RSS | %.1f MiB | %.1f MiB | %.1f MiB |\n"
                  "| GPU buffers | %.1f MiB | %.1f MiB | %.1f MiB |\n\n"
                  "Rendered pixels not finite: %llu of %llu.%s\n",
                  start.frame + 1, end.frame + 1, mib(start.rss), mib(peak.rss), mib(end.rss),
                  mib(start.gpuBuffers), mib(peak.gpuBuffers), mib(end.gpuBuffers),
                  (unsigned long long)nonFinitePixels_, (unsigned long long)renderedPixels_,
                  world_.degradedNote().c_str());
    return text;
  }

  void render(int f, const Camera& cam, FrameMetrics& m, GiFrameMetrics& g) {
    const HdrFrame frame = world_.renderFrame(cam, o_.width, o_.height, &g.shadeMilliseconds);
    if (const GiRenderer* renderer = world_.renderer()) {
      // The trace pass is now the shading pass: primary rays + their direct light.
      m.traceMilliseconds = g.shadeMilliseconds;
      g.sampleMilliseconds = renderer->lastTimes().sampleMilliseconds;
      g.objectPixels = frame.objectHits;
    }
    const std::vector<glm::vec3> pixels = frame.final();
    for (const glm::vec3& p : pixels)
      nonFinitePixels_ += !(std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z));
    renderedPixels_ += pixels.size();
    writeFrame(f, frame);
  }

  void writeFrame(int f, const HdrFrame& frame) const {
    const int w = o_.width, h = o_.height;
    const float ev = world_.render().exposureStops;
    char name[64];
    std::snprintf(name, sizeof name, "frame-%04d.png", f);
    writePng(o_.out / "frames" / name, toneMap(frame.final(), w, h, ev));
    if (!o_.layers) return;
    std::snprintf(name, sizeof name, "frame-%04d-direct.png", f);
    writePng(o_.out / "frames" / name, toneMap(frame.direct, w, h, ev));
    // Outdoors the indirect light is a few percent of the sun's: 2 stops brighter, so its
    // detail (the objects' indirect shadows) shows.
    std::snprintf(name, sizeof name, "frame-%04d-indirect.png", f);
    writePng(o_.out / "frames" / name, toneMap(frame.indirect, w, h, ev + kIndirectLayerStops));
  }

  const FlyOptions& o_;
  std::unique_ptr<gpu::Context> context_;
  StreamedGi world_;
  FlyPath path_;
  double length_;
  SceneLights sweepBase_;  // the lights as given: the sun sweep's reference
  std::vector<FrameMetrics> metrics_;
  std::vector<MemorySample> memory_;
  StreamFrameStats lastStream_{};
  std::size_t lastCachedTiles_ = 0;
  std::uint64_t nonFinitePixels_ = 0, renderedPixels_ = 0;
  std::vector<GiFrameMetrics> giMetrics_;
};

}  // namespace

int runFly(const FlyOptions& options) {
  FlyThrough flight(options);
  flight.printStart();
  flight.warmUp();
  flight.fly();
  return flight.writeOutputs();
}

}  // namespace sdfstream
