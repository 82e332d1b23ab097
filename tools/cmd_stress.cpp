// sdfstream stress (issue 7): many moving objects against the static-only GI, headless. Streams a
// world pack around a fixed camera until the cascades settle, then, on that frozen stack, runs
// the GI for a number of frames per configuration -- static-only first (no object scene, and
// once more as the noise floor), then for each object count the same spread, scripted instances
// traced through the macro-region lists and naively (every probe ray against every instance) --
// and reports GPU time per pass against the object count, checks for NaN and validation
// messages, and the goal. The report is tools/stress_report.h.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "core/atomic_dir.h"
#include "core/error.h"
#include "gi/cpu_tracer.h"
#include "gi/gi_system.h"
#include "gpu/context.h"
#include "objects/instance_set.h"
#include "objects/object_library.h"
#include "objects/scripted_motion.h"
#include "streaming/cascade_stack.h"
#include "streaming/pack_store.h"
#include "tools/args.h"
#include "tools/commands.h"
#include "tools/stress_report.h"
#include "tools/view_renderer.h"

namespace fs = std::filesystem;

namespace sdfstream::cli {
namespace {

using Clock = std::chrono::steady_clock;
using stress::Mode;
using stress::StressFrame;
using stress::StressRun;

constexpr std::uint32_t kMaxObjects = 1000000;
constexpr int kCheckEvery = 100;  // measured frames between irradiance checks / progress lines

[[noreturn]] void usage(const std::string& what) {
  throw InputError(InputErrorKind::Usage, "command line", what);
}

// "0,10,100" -> {0, 10, 100}: sorted, duplicates dropped. Anything else is a usage error that
// quotes the whole value.
std::vector<std::uint32_t> parseObjectCounts(const std::string& text) {
  auto bad = [&](const std::string& why) {
    usage("--objects expects comma-separated object counts in [0, " + std::to_string(kMaxObjects) +
          "] (e.g. 0,10,100), got '" + text + "': " + why);
  };
  std::vector<std::uint32_t> counts;
  std::size_t start = 0;
  while (true) {
    const std::size_t comma = text.find(',', start);
    const std::string item =
        text.substr(start, comma == std::string::npos ? std::string::npos : comma - start);
    if (item.empty()) bad("empty entry");
    if (item.find_first_not_of("0123456789") != std::string::npos)
      bad("'" + item + "' is not a non-negative integer");
    if (item.size() > 7 || std::stoul(item) > kMaxObjects) bad("'" + item + "' is too large");
    counts.push_back(std::uint32_t(std::stoul(item)));
    if (comma == std::string::npos) break;
    start = comma + 1;
  }
  std::sort(counts.begin(), counts.end());
  counts.erase(std::unique(counts.begin(), counts.end()), counts.end());
  return counts;
}

std::optional<glm::dvec3> parseCamera(const Args& args) {
  const auto text = args.value("--camera");
  if (!text) return std::nullopt;
  glm::dvec3 p;
  char tail = 0;
  if (std::sscanf(text->c_str(), "%lf,%lf,%lf%c", &p.x, &p.y, &p.z, &tail) != 3 ||
      !std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z))
    usage("--camera expects x,y,z (world metres), got '" + *text + "'");
  return p;
}

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
  std::uint64_t seed = 1;
  int frames = 0, warmup = 0;
};

StressRun runOnce(Bench& b, Mode mode, std::uint32_t objects) {
  StressRun run;
  run.mode = mode;
  run.objects = objects;
  const auto start = Clock::now();
  const std::uint64_t validationBefore = gpu::Context::processValidationMessageCount();
  {
    // A fresh GiSystem per run: every run starts from the same state, so the rays traced of the
    // static-only and the 0-object runs must agree frame by frame.
    GiSystem gi(b.context, b.settings, std::uint32_t(b.stack.cascadeCount()));
    InstanceSet instances;
    ScriptedMotion motion;
    if (stress::hasObjects(mode)) {
      motion = spreadObjects(instances, b.library, objects, b.area, b.seed);
      gi.setObjects(&b.library, &instances);
      gi.objects().setNaiveTraversal(mode == Mode::Naive);
    }
    SceneLights lights = b.lights;
    lights.version = 0;
    for (int f = 0; f < b.warmup + b.frames; ++f) {
      const auto t0 = Clock::now();
      if (stress::hasObjects(mode)) motion.apply(instances, f / 60.0);
      const std::span<const std::uint32_t> dirty =
          f == 0 ? std::span<const std::uint32_t>(b.allSlots) : std::span<const std::uint32_t>();
      const GiFrameStats s = gi.update(b.stack, dirty, lights, b.inputs, std::uint64_t(f));
      const double hostMs = std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
      if (f < b.warmup) continue;

      StressFrame m;
      m.frame = f;
      for (const gpu::PassTiming& t : gi.objects().lastTimings()) {
        if (!stress::hasObjects(mode)) break;  // never updated: nothing of this run
        if (t.name == "object_regions_count") m.regionCountMs += t.milliseconds;
        if (t.name == "object_regions_scan") m.regionScanMs += t.milliseconds;
        if (t.name == "object_regions_fill") m.regionFillMs += t.milliseconds;
      }
      for (const gpu::PassTiming& t : gi.probes().lastTimings())
        if (t.name == "probe_trace") m.traceMs += t.milliseconds;
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
      m.hostMs = hostMs;
      run.frames.push_back(m);

      const int measured = f - b.warmup + 1;
      if (measured % kCheckEvery == 0 || measured == b.frames) {
        const std::uint64_t bad = countNonFinite(gi.probes().downloadIrradiance());
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
  run.wallSeconds = std::chrono::duration<double>(Clock::now() - start).count();
  return run;
}

const char* kHelp =
    "usage: sdfstream stress WORLD [--objects LIST] [--frames N] [--warmup N] [--out DIR]\n"
    "                        [--seed S] [--no-naive] [--naive-max N] [--device NAME]\n"
    "                        [--validation] [options]\n"
    "\n"
    "The moving-object stress benchmark (issue 7), headless. Streams the world pack WORLD around\n"
    "a fixed camera until its cascades settle, then freezes the stack and runs the GI (default\n"
    "settings) for --frames measured frames per configuration, each on a fresh GI system:\n"
    "static-only first (no object scene; repeated once, after the 0-object run, as the noise\n"
    "floor), then per object count N the same N boxes and spheres spread over an area around\n"
    "the camera, moved by scripted orbits, falls and loops every frame, traced through the\n"
    "macro-region lists (regions) and then by testing every probe ray against every object\n"
    "(naive). Records per frame the region passes' GPU time (count, scan,\n"
    "fill), the probe update and its probe_trace pass, the light cache and the pages it relit,\n"
    "rays traced and the object rays, hits and steps; downloads every probe's irradiance every\n"
    "100 frames and at the end to count non-finite texels; counts validation messages.\n"
    "Writes DIR/results.csv (one row per count and mode), DIR/frames.csv (every frame),\n"
    "DIR/summary.md (the table, the goal check: 10,000 objects cost <= 1.5x the static-only\n"
    "probe update, and the 0-object run = static-only check) and DIR/probe-update.png,\n"
    "probe-trace.png, region-build.png (ms vs object count). DIR is replaced atomically after\n"
    "every run, so a run stopped early leaves the results of the runs it finished.\n"
    "Exit code 1 when a texel is non-finite, a validation message came, or the 0-object run\n"
    "did any object work (a region pass, a probe ray searching objects); a missed goal is\n"
    "reported, not an error.\n"
    "\n"
    "  --objects LIST     object counts, comma-separated (default 0,10,100,1000,10000)\n"
    "  --frames N         measured frames per run (default 1000)\n"
    "  --warmup N         frames before measuring, per run (default 60; frame 0 relights\n"
    "                     everything and wakes every probe)\n"
    "  --out DIR          output directory (default out/stress)\n"
    "  --seed S           object placement and motion seed (default 1)\n"
    "  --no-naive         skip the naive runs\n"
    "  --naive-max N      skip the naive runs above N objects (default: no limit)\n"
    "  --cascades N       cascades (default 6, at most the pack's LOD count)\n"
    "  --camera x,y,z     camera position (default: above the centre of the world's bounds,\n"
    "                     2 m over the surface below it); it looks along -z, slightly down\n"
    "  --area-width M     width of the square the objects are spread over, centred under the\n"
    "                     camera (default 256 cascade-0 voxels: cascade 1's width)\n"
    "  --area-height M    height of that area above the surface below the camera (default 16\n"
    "                     cascade-0 voxels: one macro region of cascade 0)\n"
    "  --probe-rays N     rays per probe (default 128)\n"
    "  --probe-budget N   probe rays per frame, all cascades (default 2097152; on a CPU Vulkan\n"
    "                     device 65536)\n"
    "  --sun dx,dy,dz,E --sky r,g,b[,r,g,b]   lights, as for render (same defaults)\n"
    "  --device NAME      Vulkan device (index or name substring; default the best one)\n"
    "  --validation       enable the Khronos validation layer and count its messages\n";

}  // namespace

int runStress(int argc, char** argv) {
  Args args(argc, argv, 2,
            {"--objects", "--frames", "--warmup", "--out", "--seed", "--naive-max", "--device",
             "--cascades", "--camera", "--area-width", "--area-height", "--probe-rays",
             "--probe-budget", "--sun", "--sky"},
            {"--help", "-h", "--no-naive", "--validation"});
  if (args.has("--help") || args.has("-h")) {
    std::fputs(kHelp, stdout);
    return 0;
  }
  if (args.positional().size() != 1)
    usage("expected: sdfstream stress WORLD [options] (see --help)");
  const fs::path world = args.positional()[0];
  const std::vector<std::uint32_t> counts =
      parseObjectCounts(args.value("--objects").value_or("0,10,100,1000,10000"));
  const int frames = args.integer("--frames", 1000, 1, 1000000);
  const int warmup = args.integer("--warmup", 60, 0, 1000000);
  const fs::path out = args.value("--out").value_or("out/stress");
  const int seed = args.integer("--seed", 1, 0, std::numeric_limits<int>::max());
  const std::uint32_t naiveMax =
      args.value("--naive-max") ? std::uint32_t(args.integer("--naive-max", 0, 0, int(kMaxObjects)))
                                : kMaxObjects;
  const std::optional<glm::dvec3> cameraArg = parseCamera(args);
  const double areaWidthArg = args.number("--area-width", 0.0);  // 0: the default, below
  const double areaHeightArg = args.number("--area-height", 0.0);
  for (const char* name : {"--area-width", "--area-height"})
    if (args.value(name) && !(args.number(name, 0.0) > 0.0))
      usage(std::string(name) + " must be > 0 (metres), got '" + *args.value(name) + "'");
  if (!fs::is_directory(world))
    throw InputError(
        InputErrorKind::Io, world.string(),
        fs::exists(world) ? "not a world pack (a pack is a directory)" : "no such world pack");

  PackTileStore store(world);  // InputError naming the manifest when it is missing or malformed
  const PackManifest& manifest = store.manifest();
  std::unique_ptr<gpu::Context> context = gpuContextFromArgs(args);
  const std::uint32_t defaultBudget = context->isSoftware() ? 1u << 16 : 1u << 21;
  const RenderOptions render = renderOptionsFromArgs(args, false, 1, defaultBudget);

  StreamingOptions so;
  so.cascades = args.integer("--cascades", 6, 1, 8);
  TileLoader loader(store, LoaderOptions{});
  CascadeStack stack(store, loader, so);

  // The camera: where asked, else 2 m (at most a quarter of the world's height) over the surface
  // below the centre of the bounds, found by settling above it and tracing straight down.
  const glm::dvec3 view = glm::normalize(glm::dvec3(0.0, -0.25, -1.0));
  const glm::dvec3 centre = 0.5 * (manifest.boundsMin + manifest.boundsMax);
  const double voxel0 = stack.voxelSize(0);
  glm::dvec3 camera =
      cameraArg.value_or(glm::dvec3(centre.x, manifest.boundsMax.y + voxel0, centre.z));
  double ground = manifest.boundsMin.y;
  std::string cameraText;
  if (!settle(stack, loader, camera, view))
    std::fprintf(stderr, "stress: warning: the cascades did not settle around %s\n",
                 describe(camera).c_str());
  const std::optional<double> below = groundBelow(stack, camera);
  if (below) ground = *below;
  if (!cameraArg) {
    const double lift =
        std::max(2.0 * voxel0, std::min(2.0, 0.25 * (manifest.boundsMax.y - manifest.boundsMin.y)));
    camera.y = ground + lift;
    char lifted[64];
    std::snprintf(lifted, sizeof lifted, ", %.2f m over ", lift);
    cameraText = describe(camera) + lifted +
                 (below ? "the surface below the centre of the world's bounds"
                        : "the bottom of the bounds (no surface found below the centre)");
    if (!settle(stack, loader, camera, view))
      std::fprintf(stderr, "stress: warning: the cascades did not settle around %s\n",
                   describe(camera).c_str());
  } else {
    cameraText = describe(camera) + " (--camera)";
  }
  stack.takeDirtySlots();
  cameraText += ", looking along -z, slightly down; still while measured";

  const GiSettings& settings = render.renderer.settings;
  Bench bench(*context, stack);
  bench.settings = settings;
  bench.lights = render.lights;
  for (std::uint32_t i = 0; i < stack.options().atlasSlots; ++i) bench.allSlots.push_back(i);
  bench.inputs.cameraWorld = camera;
  bench.inputs.viewDirection = glm::vec3(view);
  bench.seed = std::uint64_t(seed);
  bench.frames = frames;
  bench.warmup = warmup;
  const double areaWidth = areaWidthArg > 0.0 ? areaWidthArg : 256.0 * voxel0;
  const double areaHeight = areaHeightArg > 0.0 ? areaHeightArg : 16.0 * voxel0;
  bench.area.min = glm::dvec3(camera.x - areaWidth / 2, ground, camera.z - areaWidth / 2);
  bench.area.max =
      glm::dvec3(camera.x + areaWidth / 2, ground + areaHeight, camera.z + areaWidth / 2);

  stress::StressSetup setup;
  setup.world = world.string();
  setup.device = context->deviceName();
  setup.software = context->isSoftware();
  setup.validation = context->validationEnabled();
  setup.cascades = stack.cascadeCount();
  setup.regionCascades = int(std::min<std::uint32_t>(settings.objects.regionCascades,
                                                     std::uint32_t(stack.cascadeCount())));
  setup.frames = frames;
  setup.warmup = warmup;
  setup.probeBudget = settings.probes.rayBudget;
  setup.raysPerProbe = settings.probes.raysPerProbe;
  setup.voxel0 = voxel0;
  setup.camera = cameraText;
  char areaText[256];
  std::snprintf(areaText, sizeof areaText,
                "spread over %.1f x %.1f x %.1f m (x, y, z) from %s to %s: the ground below the "
                "camera up to %.1f m above it",
                areaWidth, areaHeight, areaWidth, describe(bench.area.min).c_str(),
                describe(bench.area.max).c_str(), areaHeight);
  setup.area = areaText;
  setup.seed = std::uint64_t(seed);
  for (int i = 0; i < argc; ++i) setup.command += (i ? " " : "") + std::string(argv[i]);

  std::string countText;
  for (std::uint32_t c : counts) countText += (countText.empty() ? "" : ",") + std::to_string(c);
  std::printf(
      "stress: %s on %s%s, %d cascades (voxel %.3g m), camera %s; objects %s; %d frames per run "
      "after %d warm-up frames; validation %s\n",
      world.c_str(), context->deviceName().c_str(), context->isSoftware() ? " (CPU Vulkan)" : "",
      stack.cascadeCount(), voxel0, describe(camera).c_str(), countText.c_str(), frames, warmup,
      setup.validation ? "on" : "off");
  std::fflush(stdout);

  // Static-only, then regions and naive per count (a skipped naive run is a row too), with
  // static-only repeated after the 0-object runs (first, as counts are sorted): the noise floor of
  // the 0-object comparison, taken as close to it in time as the baseline.
  std::vector<std::pair<Mode, std::uint32_t>> plan = {{Mode::Static, 0u}};
  for (std::uint32_t n : counts) {
    plan.insert(plan.end(), {{Mode::Regions, n}, {Mode::Naive, n}});
    if (n == 0) plan.push_back({Mode::StaticRepeat, 0u});
  }
  if (counts.front() != 0) plan.insert(plan.begin() + 1, {Mode::StaticRepeat, 0u});
  setup.runsPlanned = int(plan.size());
  fs::create_directories(fs::absolute(out).parent_path());
  std::vector<StressRun> runs;
  stress::StressChecks checks;
  for (const auto& [mode, n] : plan) {
    StressRun run;
    run.mode = mode;
    run.objects = n;
    if (mode == Mode::Naive && n == 0)
      run.skipped = "no objects (nothing to test: the regions run's work)";
    else if (mode == Mode::Naive && args.has("--no-naive"))
      run.skipped = "--no-naive";
    else if (mode == Mode::Naive && n > naiveMax)
      run.skipped = "above --naive-max " + std::to_string(naiveMax);
    if (run.skipped.empty()) {
      run = runOnce(bench, mode, n);
      std::printf("stress: %s, %u objects: done in %.1f s\n", stress::modeName(mode), n,
                  run.wallSeconds);
      std::fflush(stdout);
    }
    runs.push_back(std::move(run));
    // Rewritten after every run, so a run stopped early (a time limit) leaves the finished ones.
    checks = stress::checkRuns(runs);
    AtomicDirectory dir(out);
    stress::writeStressReport(dir.staging(), setup, runs, checks);
    dir.commit();
  }
  std::printf(
      "\n%s\n%s\n%s\n%s\nstress: wrote %s (results.csv, frames.csv, summary.md, "
      "probe-update.png, probe-trace.png, region-build.png)%s\n",
      stress::stressTable(runs).c_str(), checks.zeroLine.c_str(), checks.goalLine.c_str(),
      checks.passed() ? "stress: checks passed" : "stress: checks FAILED (see summary.md)",
      out.c_str(), setup.validation ? "" : "; validation was off (--validation)");
  return checks.passed() ? 0 : 1;
}

}  // namespace sdfstream::cli
