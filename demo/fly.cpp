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
#include "demo/pack_lights.h"
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

// The brick atlas budget must fit the slot index (32 bits) and, on a GPU, the device's memory:
// refused at start-up with both figures, not discovered as an allocation failure mid-flight.
void checkAtlasBudget(double atlasMiB, std::size_t slotBytes, const gpu::Context* context) {
  const double bytes = atlasMiB * double(1 << 20);
  if (!(atlasMiB > 0.0) || bytes / double(slotBytes) > double(UINT32_MAX))
    throw InputError(
        InputErrorKind::Usage, "command line",
        "--atlas-mib " + std::to_string(atlasMiB) + ": expected 0 < MiB <= " +
            std::to_string(std::uint64_t(double(UINT32_MAX) * double(slotBytes)) >> 20));
  if (context && bytes > double(context->deviceLocalBytes())) {
    char text[256];
    std::snprintf(text, sizeof text,
                  "--atlas-mib %.0f: a brick atlas budget of %.0f MiB exceeds the %.0f MiB of "
                  "device-local memory of %s",
                  atlasMiB, atlasMiB, double(context->deviceLocalBytes()) / double(1 << 20),
                  context->deviceName().c_str());
    throw InputError(InputErrorKind::TooLarge, "command line", text);
  }
}

StreamingOptions streamingOptions(const FlyOptions& o, const gpu::Context* context) {
  StreamingOptions so;
  so.cascades = o.cascades;
  const std::size_t slotBytes = 4 * (layout::kBrickDistanceWords + 2 * layout::kBrickMaterialCount);
  checkAtlasBudget(o.atlasMiB, slotBytes, context);
  so.atlasSlots = std::uint32_t(o.atlasMiB * double(1 << 20) / slotBytes);
  so.uploadBytesPerFrame = std::size_t(o.uploadMiB * double(1 << 20));
  return so;
}

LoaderOptions loaderOptions(const FlyOptions& o) {
  LoaderOptions lo;
  lo.threads = o.loaderThreads;
  return lo;
}

RenderOptions renderOptionsFor(const FlyOptions& o, const PackManifest& manifest,
                               const gpu::Context* context) {
  RenderOptions render = o.render;
  useOwnLights(render, manifest.lights, o.world.string());  // the manifest the store already read
  resolveDeviceBudgets(render.renderer.settings, context);
  return render;
}

// One fly-through, set up by the constructor (pack, path, device, stack, renderer, objects) and
// run in steps: warmUp, fly (every frame), writeOutputs.
class FlyThrough {
 public:
  explicit FlyThrough(const FlyOptions& o)
      : o_(o),
        store_(o.world),
        path_(o.path ? readFlyPath(*o.path)
                     : defaultFlyPath(store_.manifest().boundsMin, store_.manifest().boundsMax)),
        length_(path_.length()),
        context_(o.device ? gpu::Context::create(*o.device) : nullptr),
        render_(renderOptionsFor(o, store_.manifest(), context_.get())),
        loader_(store_, loaderOptions(o)),
        stack_(store_, loader_, streamingOptions(o, context_.get())) {
    if (context_)
      renderer_ = std::make_unique<GiRenderer>(*context_, render_.renderer,
                                               std::uint32_t(stack_.cascadeCount()));
    if (renderer_) reserveAtlas();
    if (renderer_ && o.objects > 0) placeObjects();
    fs::create_directories(o.out / "frames");
  }

  void printStart() const {
    std::printf(
        "fly: %s, %d frames along %.0f m at %.1f m/s, %d cascades, atlas %.0f MiB, GI %s "
        "(%u probe rays per frame), %zu moving objects, on %s\n",
        o_.world.c_str(), o_.frames, length_, o_.speed, stack_.cascadeCount(),
        double(stack_.atlasBytes()) / (1 << 20), render_.gi ? "on" : "off",
        render_.renderer.settings.probes.rayBudget, objects_ ? objects_->instances.size() : 0,
        context_ ? context_->deviceName().c_str() : "CPU reference");
  }

  // GI frames at the start of the path, streaming too; their loader stats stay out of the
  // metrics.
  void warmUp() {
    for (int w = 0; w < o_.warmupGiFrames; ++w) {
      const Camera cam = cameraAt(0.0);
      if (objects_) objects_->apply(0.0);
      stack_.update(cam.position, glm::normalize(cam.target - cam.position));
      giUpdate(cam);
    }
    if (o_.warmupGiFrames > 0) loader_.takeStats();
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
    const bool gi = renderer_ && renderer_->giEnabled();
    const std::string giMd =
        giSummaryMarkdown(giMetrics_, gi, render_.renderer.settings.probes,
                          renderer_ ? renderer_->probeDeviceBytes() : 0) +
        relightSummaryMarkdown(giMetrics_, gi, render_.renderer.settings.light.relightPageBudget) +
        objectSummaryMarkdown(giMetrics_, gi);
    std::string md = "# Fly-through summary\n\nWorld: " + o_.world.string() + "\n\n" +
                     summaryMarkdown(summary) + giMd + memoryMarkdown();
    const auto failed = loader_.failedTiles();
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
    const PackManifest& manifest = store_.manifest();
    PackGround ground(store_, manifest.boundsMin.y, manifest.boundsMax.y);
    FlyObjectsSettings os;
    os.count = o_.objects;
    os.sBegin = std::min(15.0, length_);
    os.sEnd = std::min(length_, o_.speed * (o_.frames - 1) / 30.0 + 90.0);
    objects_ = flyObjects(ground, path_, os);
    renderer_->setObjects(&objects_->library, &objects_->instances);
  }

  Camera cameraAt(double s) const {
    Camera cam;
    cam.position = path_.position(s);
    const glm::dvec3 dir = path_.direction(s);
    cam.target = cam.position + glm::normalize(dir + glm::dvec3(0.0, -0.25, 0.0)) * 10.0;
    cam.fovYDegrees = 60.0;
    return cam;
  }

  // One GI frame on the stack as it stands: sync the atlas slots the stack rewrote, relight,
  // update the probes.
  GiFrameStats giUpdate(const Camera& cam) {
    std::vector<std::uint32_t> dirty = stack_.takeDirtySlots();
    if (!renderer_) return GiFrameStats{};
    if (reuploadAtlas_) {  // the atlas was given back and reserved again: it holds nothing
      dirty.resize(stack_.atlasSlots());
      for (std::uint32_t s = 0; s < stack_.atlasSlots(); ++s) dirty[s] = s;
      reuploadAtlas_ = false;
    }
    probe::ProbeFrameInputs inputs;
    inputs.cameraWorld = cam.position;
    inputs.viewDirection = glm::vec3(glm::normalize(cam.target - cam.position));
    return renderer_->update(stack_, dirty, render_.lights, inputs, giFrame_++);
  }

  // The GPU part of a frame (GI update, and the image when this frame is written). When the
  // device runs out of memory mid-run (another process took it, or a pass grew), the brick
  // atlas, the one large buffer whose size is a choice, gives back half its slots and the GPU
  // part runs again: fewer resident bricks (the rest count as atlas-full pages), not a crash.
  // At the atlas's floor the error stands.
  template <typename Work>
  void withinDeviceMemory(int f, const Work& work) {
    for (;;) {
      try {
        if (f == injectOutOfMemoryFrame_) {
          injectOutOfMemoryFrame_ = -1;
          throw gpu::OutOfDeviceMemory("injected by SDFSTREAM_INJECT_DEVICE_OOM_FRAME");
        }
        work();
        return;
      } catch (const gpu::OutOfDeviceMemory& e) {
        if (!renderer_) throw;
        const std::uint32_t before = stack_.atlasSlots();
        const std::uint32_t got = renderer_->shrinkAtlasSlots(before / 2);  // throws at the floor
        stack_.limitAtlasSlots(got);
        if (!atlasSlotsWanted_) atlasSlotsWanted_ = before;
        ++atlasShrinks_;
        reuploadAtlas_ = true;
        std::fprintf(stderr,
                     "note: frame %d ran out of device memory (%s): the brick atlas keeps %u of "
                     "its %u slots (%.1f MiB); fewer bricks stay resident, the rest are counted "
                     "as atlas-full pages\n",
                     f, e.what(), got, before, double(stack_.atlasBytes()) / (1 << 20));
      }
    }
  }

  // Stream, move the objects, update the GI, and render when this frame is written.
  void frame(int f, double seconds) {
    const double travelled = o_.speed * seconds;
    const Camera cam = cameraAt(o_.loop ? pingPong(travelled, length_) : travelled);
    if (o_.sunDegreesPerFrame != 0.0) turnSuns();
    FrameMetrics m;
    m.frame = f;
    m.seconds = seconds;
    m.camera = cam.position;
    const auto t0 = Clock::now();
    m.stream = stack_.update(cam.position, glm::normalize(cam.target - cam.position));
    m.updateMilliseconds = millisecondsSince(t0);
    GiFrameMetrics g;
    g.frame = f;
    if (objects_) objects_->apply(seconds);  // the GI update below consumes the moves
    withinDeviceMemory(f, [&] {
      g.gi = giUpdate(cam);
      if (renderer_) g.probePasses = renderer_->lastTimes().probePasses;
      m.gpuBytes =
          stack_.atlasBytes() + std::size_t(stack_.cascadeCount()) * layout::kCascadePageCount * 4;
      if (f % o_.imageEvery == 0 || f == o_.frames - 1) render(f, cam, m, g);
    });
    m.loader = loader_.takeStats();
    lastStream_ = m.stream;
    lastCachedTiles_ = m.loader.cachedTiles;
    if (f % std::max(1, o_.metricsEvery) == 0 || f == o_.frames - 1) {
      giMetrics_.push_back(std::move(g));
      metrics_.push_back(std::move(m));
    }
  }

  // The atlas on the device before the first frame: with too little device memory for the
  // budget, fewer slots (fewer resident bricks; the rest count as atlas-full pages) instead of
  // an allocation failure.
  void reserveAtlas() {
    const std::uint32_t want = stack_.atlasSlots();
    const std::uint32_t got = renderer_->reserveAtlasSlots(want);
    if (got >= want) return;
    stack_.limitAtlasSlots(got);
    atlasSlotsWanted_ = want;
    std::fprintf(stderr,
                 "note: the device's memory holds %u of the %u brick atlas slots asked for "
                 "(%.1f of %.1f MiB): fewer bricks stay resident, the rest are counted as "
                 "atlas-full pages\n",
                 got, want, double(stack_.atlasBytes()) / (1 << 20),
                 double(want) * double(stack_.atlasBytes()) / double(got) / (1 << 20));
  }

  void turnSuns() {
    const float a = float(o_.sunDegreesPerFrame * 3.14159265358979323846 / 180.0);
    const float c = std::cos(a), s = std::sin(a);
    for (SceneLight& l : render_.lights.lights)
      if (l.type == SceneLight::Type::Sun)
        l.direction = glm::vec3(c * l.direction.x + s * l.direction.z, l.direction.y,
                                -s * l.direction.x + c * l.direction.z);
    ++render_.lights.version;
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
                  degradedNote().c_str());
    return text;
  }

  void render(int f, const Camera& cam, FrameMetrics& m, GiFrameMetrics& g) {
    const CascadeStackImage img = stack_.stackImage();
    HdrFrame frame;
    if (renderer_) {
      frame = renderer_->render(cam, o_.width, o_.height, img, render_.lights);
      // The trace pass is now the shading pass: primary rays + their direct light.
      m.traceMilliseconds = renderer_->lastTimes().shadeMilliseconds;
      g.shadeMilliseconds = m.traceMilliseconds;
      g.sampleMilliseconds = renderer_->lastTimes().sampleMilliseconds;
      g.objectPixels = frame.objectHits;
    } else {
      const auto rays = cameraRays(cam, o_.width, o_.height, img);
      const auto t1 = Clock::now();
      frame = composeFrame(shadePrimaryCpu(img, rays, toGpu(render_.lights.lights, img),
                                           toGpu(render_.lights.sky), render_.renderer.shading, {}),
                           o_.width, o_.height, {}, {});
      g.shadeMilliseconds = millisecondsSince(t1);
    }
    const std::vector<glm::vec3> pixels = frame.final();
    for (const glm::vec3& p : pixels)
      nonFinitePixels_ += !(std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z));
    renderedPixels_ += pixels.size();
    writeFrame(f, frame);
  }

  void writeFrame(int f, const HdrFrame& frame) const {
    const int w = o_.width, h = o_.height;
    const float ev = render_.exposureStops;
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
  PackTileStore store_;
  FlyPath path_;
  double length_;
  std::unique_ptr<gpu::Context> context_;
  RenderOptions render_;
  TileLoader loader_;
  CascadeStack stack_;
  std::unique_ptr<GiRenderer> renderer_;
  std::unique_ptr<DemoObjects> objects_;
  std::uint64_t giFrame_ = 0;
  std::vector<FrameMetrics> metrics_;
  std::vector<MemorySample> memory_;
  StreamFrameStats lastStream_{};
  std::size_t lastCachedTiles_ = 0;
  std::uint64_t nonFinitePixels_ = 0, renderedPixels_ = 0;
  std::uint32_t atlasSlotsWanted_ = 0;  // non-zero: the device held fewer slots (reserveAtlas)
  int atlasShrinks_ = 0;                // mid-run shrinks after running out of device memory
  bool reuploadAtlas_ = false;          // the next GI update uploads every slot
  // Test hook: SDFSTREAM_INJECT_DEVICE_OOM_FRAME=F makes frame F's GPU part fail once as an
  // allocation would, so the recovery above is tested at a known frame, not at whichever frame
  // the loader's timing makes a pass grow.
  int injectOutOfMemoryFrame_ = [] {
    const char* v = std::getenv("SDFSTREAM_INJECT_DEVICE_OOM_FRAME");
    return v && *v ? std::atoi(v) : -1;
  }();

  std::string degradedNote() const {
    if (!atlasSlotsWanted_) return "";
    std::string note = " Device memory held " + std::to_string(stack_.atlasSlots()) + " of the " +
                       std::to_string(atlasSlotsWanted_) +
                       " atlas slots asked for (fewer resident bricks)";
    if (atlasShrinks_ > 0)
      note += "; the atlas shrank " + std::to_string(atlasShrinks_) +
              (atlasShrinks_ == 1 ? " time" : " times") +
              " mid-run when the device ran out of memory";
    return note + ".";
  }
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
