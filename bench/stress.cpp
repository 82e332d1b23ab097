#include "bench/stress.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <memory>
#include <span>
#include <utility>

#include "bench/stress_report.h"
#include "core/atomic_dir.h"
#include "core/error.h"
#include "core/stopwatch.h"
#include "demo/render_options.h"
#include "gi/cpu_tracer.h"
#include "objects/instance_set.h"
#include "objects/object_library.h"
#include "objects/scripted_motion.h"
#include "streaming/cascade_stack.h"
#include "streaming/pack_store.h"

namespace fs = std::filesystem;

namespace sdfstream::bench {
namespace {

using Clock = std::chrono::steady_clock;
using stress::Mode;
using stress::StressFrame;
using stress::StressRun;

constexpr int kCheckEvery = 100;  // measured frames between irradiance checks / progress lines

// Streams until every cascade holds what it needs; false if that never happens (atlas too
// small, tiles failing): the run goes on with what is resident.
bool settle(CascadeStack& stack, TileLoader& loader, glm::dvec3 camera, glm::dvec3 view) {
  for (int i = 0; i < 2000; ++i) {
    stack.update(camera, view);
    if (stack.settled()) return true;
    loader.waitIdle();
  }
  return false;
}

// Height of the first surface straight below `from`, by tracing the settled stack on the CPU.
std::optional<double> groundBelow(const CascadeStack& stack, glm::dvec3 from) {
  const CascadeStackImage img = stack.stackImage();
  gpu_shared::TraceRay ray{};
  ray.originTMin = glm::vec4(img.toStack(from), 0.0f);
  ray.dirTMax = glm::vec4(0.0f, -1.0f, 0.0f, 1e30f);
  const auto hit = traceStackCpu(img, {&ray, 1}, TraceSettings{});
  if (!(hit[0].flags & gpu_shared::kHitFlagHit)) return std::nullopt;
  return from.y - double(hit[0].normalT.w) * img.voxelSize0;
}

std::string describe(glm::dvec3 p) {
  char text[96];
  std::snprintf(text, sizeof text, "(%.1f, %.1f, %.1f)", p.x, p.y, p.z);
  return text;
}

std::uint64_t countNonFinite(const std::vector<glm::vec4>& texels) {
  std::uint64_t n = 0;
  for (const glm::vec4& t : texels)
    n += !(std::isfinite(t.x) && std::isfinite(t.y) && std::isfinite(t.z) && std::isfinite(t.w));
  return n;
}

// Everything the runs share: the frozen stack, the GI settings, the objects' library and area.
struct Bench {
  Bench(gpu::Context& c, const CascadeStack& s) : context(c), stack(s) {}
  gpu::Context& context;
  const CascadeStack& stack;
  std::vector<std::uint32_t> allSlots;  // frame 0 of each fresh GiSystem uploads every slot
  GiSettings settings;
  SceneLights lights;
  probe::ProbeFrameInputs inputs;
  ObjectLibrary library;  // spreadObjects adds its box and sphere once and reuses them
  WorldBox area;
  double areaWidth = 0.0, areaHeight = 0.0;  // metres: area's extent in x and z, and in y
  std::uint64_t seed = 1;
  int frames = 0, warmup = 0;
  std::uint32_t meshes = 2;
  double sunOrbitDegrees = 0.0;
};

// The lights of frame f: suns turned about the vertical by f × degrees (a sun
// that moves every frame; each frame is a light change, so everything lit is relit).
SceneLights lightsAt(const SceneLights& base, double degrees, int f) {
  SceneLights lights = base;
  lights.version = degrees != 0.0 ? std::uint64_t(f) : 0;
  if (degrees == 0.0) return lights;
  const double a = glm::radians(degrees * double(f));
  const double c = std::cos(a), s = std::sin(a);
  for (SceneLight& l : lights.lights)
    if (l.type == SceneLight::Type::Sun)
      l.direction =
          glm::normalize(glm::vec3(float(c * l.direction.x + s * l.direction.z), l.direction.y,
                                   float(-s * l.direction.x + c * l.direction.z)));
  return lights;
}

StressRun runOnce(Bench& b, Mode mode, std::uint32_t objects) {
  StressRun run;
  run.mode = mode;
  run.objects = objects;
  const auto start = Clock::now();
  const std::uint64_t validationBefore = gpu::Context::processValidationMessageCount();
  {
    // A fresh GiSystem per run: every run starts from the same state, so the rays traced of the
    // static-only and the 0-object runs must agree frame by frame.
    GiSettings settings = b.settings;
    if (mode == Mode::RegionsNoCards) settings.objects.cards = false;
    GiSystem gi(b.context, settings, std::uint32_t(b.stack.cascadeCount()));
    InstanceSet instances;
    ScriptedMotion motion;
    if (stress::hasObjects(mode)) {
      motion = spreadObjects(instances, b.library, objects, b.area, b.seed, b.meshes);
      gi.setObjects(&b.library, &instances);
      gi.objects().setNaiveTraversal(mode == Mode::Naive);
    }
    for (int f = 0; f < b.warmup + b.frames; ++f) {
      const SceneLights lights = lightsAt(b.lights, b.sunOrbitDegrees, f);
      const auto t0 = Clock::now();
      if (stress::hasObjects(mode)) motion.apply(instances, f / 60.0);
      const double motionMs = millisecondsSince(t0);
      const std::span<const std::uint32_t> dirty =
          f == 0 ? std::span<const std::uint32_t>(b.allSlots) : std::span<const std::uint32_t>();
      const GiFrameStats s = gi.update(b.stack, dirty, lights, b.inputs, std::uint64_t(f));
      const double wallMs = millisecondsSince(t0);
      if (f == 0 && mode == Mode::Regions && objects > 0) {  // the first frame captures the cards
        run.meshesCaptured = std::uint32_t(b.library.size());
        run.captureMs = gi.objects().lastCaptureMilliseconds();
        std::printf("stress: cards of %zu meshes captured in %.3f ms of GPU time\n",
                    b.library.size(), run.captureMs);
      }
      if (f < b.warmup) continue;

      StressFrame m;
      m.frame = f;
      for (const gpu::PassTiming& t : gi.objects().lastTimings()) {
        if (!stress::hasObjects(mode)) break;  // never updated: nothing of this run
        // The sub-cell lists' count and scan passes, and the rank pass, are counted with the
        // regions' count and scan.
        if (t.name == "object_regions_count" || t.name == "object_regions_subcount")
          m.regionCountMs += t.milliseconds;
        if (t.name == "object_regions_rank" || t.name == "object_regions_scan" ||
            t.name == "object_regions_subscan")
          m.regionScanMs += t.milliseconds;
        if (t.name == "object_regions_fill") m.regionFillMs += t.milliseconds;
      }
      for (const gpu::PassTiming& t : gi.probes().lastTimings())
        if (t.name == "probe_trace") m.traceMs += t.milliseconds;
      for (const gpu::PassTiming& t : s.passes)
        if (t.name == "light_cache_cards") m.cardLightMs += t.milliseconds;
      if (stress::hasObjects(mode)) {
        const CardLightSlots::Stats& cards = gi.objects().cardStats();
        m.cardRelit = cards.relit;
        m.cardStaleFrames = cards.maxStaleFrames;
        m.cardMiB = double(gi.objects().cardBytes()) / double(1 << 20);
      }
      m.probeMs = s.probeMilliseconds;
      m.lightMs = s.lightMilliseconds;
      m.pagesRelit = s.pagesRelit;
      m.objectPagesRelit = s.objectPagesRelit;
      m.probesUpdated = s.probes.probesUpdated;
      m.raysTraced = s.probes.raysTraced;
      m.raysCached = s.probes.raysCached;
      m.objectRays = s.probes.objectRays;
      m.objectHits = s.probes.objectHits;
      m.objectSteps = s.probes.objectSteps;
      m.motionMs = motionMs;
      m.host = s.host;
      m.wallMs = wallMs;
      run.frames.push_back(m);

      const int measured = f - b.warmup + 1;
      if (measured % kCheckEvery == 0 || measured == b.frames) {
        const std::uint64_t badCards =
            stress::hasObjects(mode) ? gi.objects().cardNonFiniteTexels() : 0;  // cumulative
        const std::uint64_t bad =
            countNonFinite(gi.probes().downloadIrradiance()) + (badCards - run.nonFiniteCardTexels);
        run.nonFiniteCardTexels = badCards;
        run.nonFiniteTexels += bad;
        ++run.irradianceChecks;
        const std::uint64_t messages =
            gpu::Context::processValidationMessageCount() - validationBefore;
        std::fprintf(stderr,
                     "  %s, %u objects: frame %d/%d: probe update %.3f ms (probe_trace %.3f), "
                     "regions %.3f ms, light %.3f ms, %u rays traced, %u object rays, "
                     "%llu non-finite texels, %llu validation messages\n",
                     stress::modeName(mode), objects, measured, b.frames, m.probeMs, m.traceMs,
                     m.regionMs(), m.lightMs, m.raysTraced, m.objectRays, (unsigned long long)bad,
                     (unsigned long long)messages);
      }
    }
  }
  b.context.waitIdle();  // the run's buffers are freed before the next run allocates its own
  run.validationMessages = gpu::Context::processValidationMessageCount() - validationBefore;
  run.wallSeconds = secondsSince(start);
  return run;
}

// Where the camera stands and what lies below it.
struct CameraPlacement {
  glm::dvec3 camera{0.0};
  double ground = 0.0;  // world y of the surface below the camera (or the bounds' bottom)
  std::string text;     // for the summary
};

// The camera: where asked, else 2 m (at most a quarter of the world's height) over the surface
// below the centre of the bounds, found by settling above it and tracing straight down. Leaves
// the stack settled around it.
CameraPlacement placeCamera(CascadeStack& stack, TileLoader& loader, const PackManifest& manifest,
                            const std::optional<glm::dvec3>& asked, glm::dvec3 view) {
  const glm::dvec3 centre = 0.5 * (manifest.boundsMin + manifest.boundsMax);
  const double voxel0 = stack.voxelSize(0);
  CameraPlacement p;
  p.camera = asked.value_or(glm::dvec3(centre.x, manifest.boundsMax.y + voxel0, centre.z));
  p.ground = manifest.boundsMin.y;
  if (!settle(stack, loader, p.camera, view))
    std::fprintf(stderr, "stress: warning: the cascades did not settle around %s\n",
                 describe(p.camera).c_str());
  const std::optional<double> below = groundBelow(stack, p.camera);
  if (below) p.ground = *below;
  if (!asked) {
    const double lift =
        std::max(2.0 * voxel0, std::min(2.0, 0.25 * (manifest.boundsMax.y - manifest.boundsMin.y)));
    p.camera.y = p.ground + lift;
    char lifted[64];
    std::snprintf(lifted, sizeof lifted, ", %.2f m over ", lift);
    p.text = describe(p.camera) + lifted +
             (below ? "the surface below the centre of the world's bounds"
                    : "the bottom of the bounds (no surface found below the centre)");
    if (!settle(stack, loader, p.camera, view))
      std::fprintf(stderr, "stress: warning: the cascades did not settle around %s\n",
                   describe(p.camera).c_str());
  } else {
    p.text = describe(p.camera) + " (--camera)";
  }
  p.text += ", looking along -z, slightly down; still while measured";
  return p;
}

// What every run shares; the objects' area is a square centred under the camera, from the
// ground up.
void setUpBench(Bench& bench, const StressOptions& o, const GiSettings& settings,
                const CameraPlacement& at, glm::dvec3 view) {
  const double voxel0 = bench.stack.voxelSize(0);
  bench.settings = settings;
  bench.lights = o.lights;
  for (std::uint32_t i = 0; i < bench.stack.options().atlasSlots; ++i) bench.allSlots.push_back(i);
  bench.inputs.cameraWorld = at.camera;
  bench.inputs.viewDirection = glm::vec3(view);
  bench.seed = o.seed;
  bench.meshes = o.meshes;
  bench.sunOrbitDegrees = o.sunOrbitDegrees;
  bench.frames = o.frames;
  bench.warmup = o.warmup;
  const double areaWidth = o.areaWidth > 0.0 ? o.areaWidth : 256.0 * voxel0;
  const double areaHeight = o.areaHeight > 0.0 ? o.areaHeight : 16.0 * voxel0;
  bench.areaWidth = areaWidth;
  bench.areaHeight = areaHeight;
  const glm::dvec3 camera = at.camera;
  bench.area.min = glm::dvec3(camera.x - areaWidth / 2, at.ground, camera.z - areaWidth / 2);
  bench.area.max =
      glm::dvec3(camera.x + areaWidth / 2, at.ground + areaHeight, camera.z + areaWidth / 2);
}

stress::StressSetup describeSetup(const StressOptions& o, const gpu::Context& context,
                                  const Bench& bench, const CameraPlacement& at) {
  const GiSettings& settings = bench.settings;
  stress::StressSetup setup;
  setup.world = o.world.string();
  setup.device = context.deviceName();
  setup.software = context.isSoftware();
  setup.validation = context.validationEnabled();
  setup.cascades = bench.stack.cascadeCount();
  setup.regionCascades = int(std::min<std::uint32_t>(settings.objects.regionCascades,
                                                     std::uint32_t(bench.stack.cascadeCount())));
  setup.frames = o.frames;
  setup.warmup = o.warmup;
  setup.probeBudget = settings.probes.rayBudget;
  setup.raysPerProbe = settings.probes.raysPerProbe;
  setup.voxel0 = bench.stack.voxelSize(0);
  setup.camera = at.text;
  char areaText[256];
  std::snprintf(areaText, sizeof areaText,
                "spread over %.1f x %.1f x %.1f m (x, y, z) from %s to %s: the ground below the "
                "camera up to %.1f m above it",
                bench.areaWidth, bench.areaHeight, bench.areaWidth,
                describe(bench.area.min).c_str(), describe(bench.area.max).c_str(),
                bench.areaHeight);
  setup.area = areaText;
  setup.seed = o.seed;
  setup.command = o.command;
  return setup;
}

// Static-only, then regions and naive per count (a skipped naive run is a row too), with
// static-only repeated after the 0-object runs (first, as counts are sorted): the noise floor of
// the 0-object comparison, taken as close to it in time as the baseline.
std::vector<std::pair<Mode, std::uint32_t>> runPlan(const std::vector<std::uint32_t>& counts) {
  std::vector<std::pair<Mode, std::uint32_t>> plan = {{Mode::Static, 0u}};
  for (std::uint32_t n : counts) {
    plan.insert(plan.end(), {{Mode::Regions, n}, {Mode::RegionsNoCards, n}, {Mode::Naive, n}});
    if (n == 0) plan.push_back({Mode::StaticRepeat, 0u});
  }
  if (counts.front() != 0) plan.insert(plan.begin() + 1, {Mode::StaticRepeat, 0u});
  return plan;
}

// Why a planned run is skipped ("" = it is made).
std::string skipReason(const StressOptions& o, Mode mode, std::uint32_t n) {
  if (mode == Mode::RegionsNoCards)
    return n == 0 ? "no objects (the regions run's work)" : o.cardsPeer ? "" : "--no-cards-peer";
  if (mode != Mode::Naive) return "";
  if (n == 0) return "no objects (nothing to test: the regions run's work)";
  if (!o.naive) return "--no-naive";
  if (n > o.naiveMax) return "above --naive-max " + std::to_string(o.naiveMax);
  return "";
}

}  // namespace

int runStress(const StressOptions& o) {
  if (!fs::is_directory(o.world))
    throw InputError(
        InputErrorKind::Io, o.world.string(),
        fs::exists(o.world) ? "not a world pack (a pack is a directory)" : "no such world pack");
  PackTileStore store(o.world);  // InputError naming the manifest when it is missing or malformed
  std::unique_ptr<gpu::Context> context = gpu::Context::create(o.device);
  GiSettings settings = o.settings;
  resolveDeviceBudgets(settings, context.get());

  StreamingOptions so;
  so.cascades = o.cascades;
  TileLoader loader(store, LoaderOptions{});
  CascadeStack stack(store, loader, so);
  const glm::dvec3 view = glm::normalize(glm::dvec3(0.0, -0.25, -1.0));
  const CameraPlacement at = placeCamera(stack, loader, store.manifest(), o.camera, view);
  stack.takeDirtySlots();

  Bench bench(*context, stack);
  setUpBench(bench, o, settings, at, view);
  stress::StressSetup setup = describeSetup(o, *context, bench, at);
  std::string countText;
  for (std::uint32_t c : o.counts) {
    if (!countText.empty()) countText += ',';
    countText += std::to_string(c);
  }
  std::printf(
      "stress: %s on %s%s, %d cascades (voxel %.3g m), camera %s; objects %s; %d frames per run "
      "after %d warm-up frames; validation %s\n",
      o.world.c_str(), context->deviceName().c_str(), context->isSoftware() ? " (CPU Vulkan)" : "",
      stack.cascadeCount(), setup.voxel0, describe(at.camera).c_str(), countText.c_str(), o.frames,
      o.warmup, setup.validation ? "on" : "off");
  std::fflush(stdout);

  const std::vector<std::pair<Mode, std::uint32_t>> plan = runPlan(o.counts);
  setup.runsPlanned = int(plan.size());
  fs::create_directories(fs::absolute(o.out).parent_path());
  std::vector<StressRun> runs;
  stress::StressChecks checks;
  for (const auto& [mode, n] : plan) {
    StressRun run;
    run.mode = mode;
    run.objects = n;
    run.skipped = skipReason(o, mode, n);
    if (run.skipped.empty()) {
      run = runOnce(bench, mode, n);
      std::printf("stress: %s, %u objects: done in %.1f s\n", stress::modeName(mode), n,
                  run.wallSeconds);
      std::fflush(stdout);
    }
    runs.push_back(std::move(run));
    // Rewritten after every run, so a run stopped early (a time limit) leaves the finished ones.
    checks = stress::checkRuns(runs);
    AtomicDirectory dir(o.out);
    stress::writeStressReport(dir.staging(), setup, runs, checks);
    dir.commit();
  }
  std::printf(
      "\n%s\n%s\n%s\n%s\nstress: wrote %s (results.csv, frames.csv, summary.md, "
      "probe-update.png, probe-trace.png, region-build.png)%s\n",
      stress::stressTable(runs).c_str(), checks.zeroLine.c_str(), checks.goalLine.c_str(),
      checks.passed() ? "stress: checks passed" : "stress: checks FAILED (see summary.md)",
      o.out.c_str(), setup.validation ? "" : "; validation was off (--validation)");
  return checks.passed() ? 0 : 1;
}

}  // namespace sdfstream::bench
