// sdfstream stress and its host-only sibling sdfstream bench host: parse their flags; the
// benchmarks are bench/stress.h and bench/host_objects_bench.h.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "bench/host_objects_bench.h"
#include "bench/stress.h"
#include "core/error.h"
#include "tools/args.h"
#include "tools/commands.h"
#include "tools/render_args.h"

namespace sdfstream::cli {
namespace {

constexpr std::uint32_t kMaxObjects = 1000000;

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

const char* kHelp =
    "usage: sdfstream stress WORLD [--objects LIST] [--frames N] [--warmup N] [--out DIR]\n"
    "                        [--seed S] [--no-naive] [--naive-max N] [--no-cards-peer]\n"
    "                        [--meshes N] [--sun-orbit DEG] [--sub-list-entries N]\n"
    "                        [--sub-list-min-mean X] [--wake-change X] [--device NAME]\n"
    "                        [--validation] [options]\n"
    "\n"
    "The moving-object stress benchmark, headless. Streams the world pack WORLD around\n"
    "a fixed camera until its cascades settle, then freezes the stack and runs the GI (default\n"
    "settings) for --frames measured frames per configuration, each on a fresh GI system:\n"
    "static-only first (no object scene; repeated once, after the 0-object run, as the noise\n"
    "floor), then per object count N the same N boxes and spheres spread over an area around\n"
    "the camera, moved by scripted orbits, falls and loops every frame, traced through the\n"
    "macro-region lists (regions), the same with the objects' cards off (regions-no-cards: hits\n"
    "carry no direct light of their own), and by testing every probe ray against every object\n"
    "(naive). Records per frame the region passes' GPU time (count, scan,\n"
    "fill; the rank and sub-cell passes count with count and scan; short lists, which the\n"
    "host places, run the fill alone), the probe update and its probe_trace pass, the\n"
    "light cache and the pages it relit, the probes updated,\n"
    "rays traced and the object rays, hits and steps, and the host's CPU time by part (motion,\n"
    "object frame, shadow pages, ...); downloads every probe's irradiance every\n"
    "100 frames and at the end to count non-finite texels, and the card light texels whose\n"
    "radiance came out NaN or infinite (counted by the card light pass); counts validation\n"
    "messages.\n"
    "Writes DIR/results.csv (one row per count and mode), DIR/frames.csv (every frame),\n"
    "DIR/summary.md (the table, the goal check: 10,000 objects cost <= 2x the static-only\n"
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
    "  --no-cards-peer    skip the runs with the cards off\n"
    "  --meshes N         spread the objects over N distinct meshes (default 2: a box and a\n"
    "                     sphere; more adds boxes and ellipsoids of other shapes and colours,\n"
    "                     each with its own cards)\n"
    "  --sun-orbit DEG    turn the sun about the vertical by DEG degrees every frame (default 0:\n"
    "                     still); every frame is then a light change (for the probes a drift\n"
    "                     that wakes none, up to 1 degree a frame)\n"
    "  --sub-list-entries N\n"
    "                     sub-cell list capacity per frame, headers and as many entries\n"
    "                     (default 1048576); 0 walks every region with its region list alone,\n"
    "                     the walk without sub-cell lists to compare with\n"
    "  --sub-list-min-mean X\n"
    "                     build sub-cell lists only when the region lists hold at least X\n"
    "                     entries per occupied region on average (default 8; 0: always)\n"
    "  --wake-change X    a move wakes the probes whose irradiance it can change by at least\n"
    "                     this fraction (default 0.05, the probes' sleep threshold; 1: only\n"
    "                     probes inside the moved boxes): fewer woken probes cost less and\n"
    "                     follow a mover later\n"
    "  --cascades N       cascades (default 6, at most the pack's LOD count)\n"
    "  --camera x,y,z     camera position (default: above the centre of the world's bounds,\n"
    "                     2 m over the surface below it); it looks along -z, slightly down\n"
    "  --area-width M     width of the square the objects are spread over, centred under the\n"
    "                     camera (default 256 cascade-0 voxels: cascade 1's width)\n"
    "  --area-height M    height of that area above the surface below the camera (default 16\n"
    "                     cascade-0 voxels: one macro region of cascade 0)\n"
    "  --probe-rays N     rays per probe (default 128)\n"
    "  --probe-budget N   probe rays per frame, all cascades (default 1048576; on a CPU Vulkan\n"
    "                     device 65536)\n"
    "  --sun dx,dy,dz,E --sky r,g,b[,r,g,b]   lights, as for render (same defaults)\n"
    "  --device NAME      Vulkan device (index or name substring; default the best one)\n"
    "  --validation       enable the Khronos validation layer and count its messages\n";

}  // namespace

int runStress(int argc, char** argv) {
  Args args(argc, argv, 2,
            {"--objects",
             "--frames",
             "--warmup",
             "--out",
             "--seed",
             "--naive-max",
             "--device",
             "--cascades",
             "--camera",
             "--area-width",
             "--area-height",
             "--probe-rays",
             "--probe-budget",
             "--sun",
             "--sky",
             "--meshes",
             "--sun-orbit",
             "--sub-list-entries",
             "--sub-list-min-mean",
             "--wake-change"},
            {"--help", "-h", "--no-naive", "--no-cards-peer", "--validation"});
  if (args.has("--help") || args.has("-h")) {
    std::fputs(kHelp, stdout);
    return 0;
  }
  if (args.positional().size() != 1)
    usage("expected: sdfstream stress WORLD [options] (see --help)");
  bench::StressOptions o;
  o.world = args.positional()[0];
  o.counts = parseObjectCounts(args.value("--objects").value_or("0,10,100,1000,10000"));
  o.frames = args.integer("--frames", o.frames, 1, 1000000);
  o.warmup = args.integer("--warmup", o.warmup, 0, 1000000);
  o.out = args.value("--out").value_or(o.out.string());
  o.seed = std::uint64_t(args.integer("--seed", 1, 0, std::numeric_limits<int>::max()));
  o.naive = !args.has("--no-naive");
  o.cardsPeer = !args.has("--no-cards-peer");
  o.meshes = std::uint32_t(args.integer("--meshes", 2, 2, 64));
  o.sunOrbitDegrees = args.number("--sun-orbit", 0.0);
  if (!std::isfinite(o.sunOrbitDegrees) || std::abs(o.sunOrbitDegrees) > 360.0)
    usage("--sun-orbit expects degrees per frame in [-360, 360]");
  o.naiveMax = args.value("--naive-max")
                   ? std::uint32_t(args.integer("--naive-max", 0, 0, int(kMaxObjects)))
                   : kMaxObjects;
  o.camera = parseCamera(args);
  o.areaWidth = args.number("--area-width", 0.0);  // 0: the default
  o.areaHeight = args.number("--area-height", 0.0);
  for (const char* name : {"--area-width", "--area-height"})
    if (args.value(name) && !(args.number(name, 0.0) > 0.0))
      usage(std::string(name) + " must be > 0 (metres), got '" + *args.value(name) + "'");
  o.cascades = args.integer("--cascades", o.cascades, 1, 8);
  const RenderOptions render = renderOptionsFromArgs(args, false, 1, kProbeBudgetOfDevice);
  o.settings = render.renderer.settings;
  o.settings.objects.maxSubListEntries = std::uint32_t(
      args.integer("--sub-list-entries", int(o.settings.objects.maxSubListEntries), 0, 1 << 24));
  const double minMean =
      args.number("--sub-list-min-mean", o.settings.objects.subListMinMeanEntries);
  if (minMean < 0.0) usage("--sub-list-min-mean must be >= 0");
  o.settings.objects.subListMinMeanEntries = float(minMean);
  const double wakeChange = args.number("--wake-change", o.settings.objects.wakeIrradianceChange);
  if (!(wakeChange >= 1e-4 && wakeChange <= 1.0))
    usage("--wake-change must be in [0.0001, 1], got '" + *args.value("--wake-change") + "'");
  o.settings.objects.wakeIrradianceChange = float(wakeChange);
  o.lights = render.lights;
  o.device = *deviceFromArgs(args);  // no --cpu: the objects need Vulkan
  o.command = commandLine(argc, argv, 0);
  return bench::runStress(o);
}

int runBenchHost(int argc, char** argv) {
  Args args(argc, argv, 3,
            {"--objects", "--frames", "--warmup", "--meshes", "--seed", "--threads", "--out"},
            {"--help", "-h"});
  if (args.has("--help") || args.has("-h") || !args.positional().empty()) {
    std::puts(
        "usage: sdfstream bench host [--objects 100,1000,10000,100000] [--frames 120]\n"
        "       [--warmup 10] [--meshes 2] [--seed 1] [--threads N] [--out out/bench/host]\n"
        "The moving objects' host work per frame, without a GPU: at each object count the spread\n"
        "objects and scripted motion of `sdfstream stress` (all moving), a synthetic stack of 4\n"
        "cascades (1 m voxels, every page resident) and a sun; times the motion, the object frame\n"
        "(instances, changed boxes and wake bits), the card light slots and the shadow pages on\n"
        "all cores and nothing else (stress's host figures share them with the Vulkan driver).\n"
        "--threads N limits the worker threads (default: every core), to see which parts scale.\n"
        "Writes summary.md (medians by part, us per instance, scaling exponents) and results.csv.");
    return args.has("--help") || args.has("-h") ? 0 : 2;
  }
  bench::HostObjectsOptions o;
  if (auto list = args.value("--objects")) o.objects = parseObjectCounts(*list);
  o.frames = args.integer("--frames", o.frames, 1, 1000000);
  o.warmup = args.integer("--warmup", o.warmup, 0, 1000000);
  o.meshes = std::uint32_t(args.integer("--meshes", 2, 2, 64));
  o.seed = std::uint64_t(args.integer("--seed", 1, 0, std::numeric_limits<int>::max()));
  o.threads = args.integer("--threads", 0, 1, 4096);
  o.out = args.value("--out").value_or(o.out.string());
  bench::runHostObjectsBench(o);
  return 0;
}

}  // namespace sdfstream::cli
