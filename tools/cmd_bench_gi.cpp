// sdfstream bench gi: its flags (the benchmark is bench/bench_gi.h).
#include <algorithm>
#include <cstdio>
#include <sstream>
#include <string>
#include <vector>

#include "bench/bench_gi.h"
#include "bench/bench_gi_scenes.h"
#include "core/error.h"
#include "tools/args.h"
#include "tools/commands.h"

namespace sdfstream::cli {
namespace {

std::vector<std::string> splitList(const std::string& s) {
  std::vector<std::string> out;
  std::stringstream in(s);
  std::string item;
  while (std::getline(in, item, ','))
    if (!item.empty()) out.push_back(item);
  return out;
}

constexpr const char* kHelp =
    "usage: sdfstream bench gi [--quick] [--scenes a,b,...] [--out DIR] [--data DIR]\n"
    "                          [--large-world PACK] [--width W --height H] [--samples N]\n"
    "                          [--frames N] [--measure N] [--no-peers] [--gpu-table]\n"
    "                          [--diagnose] [--device NAME]\n"
    "\n"
    "Run time vs error of the probe GI. For each scene: import its triangles to a\n"
    "world pack (cached in DIR/packs), stream cascade stacks around the player, path-trace the\n"
    "reference irradiance at the visible points of the scene's views (kind NoDirectLights:\n"
    "what probes store; cached in DIR/reference), then for every configuration of the sweep\n"
    "(rays per probe, probe spacing, cascades, hit cache, states, relocation, visibility; our\n"
    "default; plain DDGI = one probe per brick, no relocation/states/hit cache, Chebyshev only)\n"
    "run the GI to convergence and measure GPU time per frame (probe update and sampling, medians\n"
    "of the pass timestamps), relMSE (top 0.1% discarded) and mean FLIP of albedo/pi*E images,\n"
    "the spread of E over each view's largest flat region against the reference's (splotches),\n"
    "frames to converge after the lights switch off and on (once the field has settled: the new\n"
    "probes' vigilant frames and 64 more), and device memory. The probe rays of\n"
    "one frame are also traced by Embree, OpenVDB and NanoVDB (2 threads) against our GPU\n"
    "traversal. Writes DIR/results.csv, DIR/summary.md, DIR/<scene>/error-vs-time.png and\n"
    "reference/default/plain-DDGI images per view.\n"
    "\n"
    "  --quick        Cornell box + one small scene (Breakfast Room, else the bunny), a reduced\n"
    "                 sweep, 96x72 views, 256 reference paths, fewer frames (<= 10 min on 2 "
    "cores)\n"
    "  --scenes LIST  of cornell-box,sponza,breakfast-room,courtyard,courtyard-sun,\n"
    "                 emissive-room,bunny,large-world (default: cornell-box,sponza,\n"
    "                 breakfast-room,courtyard,emissive-room,large-world; missing data is\n"
    "                 skipped with a message); NAME@VIEW: that view (name or index) alone,\n"
    "                 with the player (the stack's centre) at its camera\n"
    "  --out DIR      default out/bench-gi        --data DIR  default ../shared/data\n"
    "  --large-world  default out/worlds/village-4km (a pack; skipped when absent)\n"
    "  --frames N     warm-up frames per configuration (default 32, quick 8)\n"
    "  --measure N    measured frames (default 6, quick 4)\n"
    "  --samples N    reference paths per point (default 512, quick 256)\n"
    "  --no-peers     skip the traversal peers\n"
    "  --configs LIST run only these configurations (names as in results.csv)\n"
    "  --converge-cap N  most frames waited for convergence after the light change (0: skip)\n"
    "  --verbose      print every measured frame's pass times, work and probe states (off,\n"
    "                 sleeping, awake, vigilant), and the error left\n"
    "                 and the probe passes' GPU time after each frame of the light switch\n"
    "  --diagnose     also where the light goes: the default's probe rays against Embree by the\n"
    "                 cascade they end in (openings closed, surfaces early, leaks, backfaces,\n"
    "                 sky seen); the probes' irradiance (all, the receivers' cages, midway)\n"
    "                 and perfect probes against the reference; its one-bounce transport\n"
    "                 against a one-bounce reference, and ray by ray against the same rays on\n"
    "                 the triangles\n"
    "  --diagnose-config NAME  take this configuration apart instead of the default (implies\n"
    "                 --diagnose; it must be among those run)\n"
    "  --query-offset V  GI queries sit V LOD-0 voxels off the reference's points along the\n"
    "                 normal (default 0.5: on the SDF surface of an open sheet)\n"
    "  --gpu-table    only the per-pass time table of scripts/bench-gpu (SDFDDGI's probe count,\n"
    "                 our default, plain DDGI, the default at half and twice its ray budget)\n"
    "                 on the given scenes, with the full light relight's work counted on the\n"
    "                 CPU (surface cells, shadow-ray steps, warp-steps); writes\n"
    "                 DIR/gpu-table-SCENE.md and .csv\n"
    "  --rounds N     with --gpu-table: run the configurations N times in turn and keep each\n"
    "                 one's fastest round (a GPU's clocks can change within a run; default 1)\n"
    "  --settled-frames N  with --gpu-table: after the measured frames run on to frame N and\n"
    "                 measure again, the settled field's cost beside the young one's (default\n"
    "                 160; 0: skip)\n";

}  // namespace

int runBenchGi(int argc, char** argv) {
  Args args(argc, argv, 3,
            {"--scenes", "--out", "-o", "--data", "--large-world", "--width", "--height",
             "--samples", "--frames", "--measure", "--device", "--converge-cap", "--configs",
             "--query-offset", "--diagnose-config", "--rounds", "--settled-frames"},
            {"--help", "-h", "--quick", "--no-peers", "--gpu-table", "--validation", "--verbose",
             "--diagnose"});
  if (args.has("--help") || args.has("-h")) {
    std::fputs(kHelp, stdout);
    return 0;
  }
  if (!args.positional().empty())
    throw InputError(InputErrorKind::Usage, "command line",
                     "bench gi takes no positional arguments (see --help)");
  bench::GiBenchOptions opt;
  opt.quick = args.has("--quick");
  opt.gpuTable = args.has("--gpu-table");
  opt.peers = !args.has("--no-peers") && !opt.gpuTable;
  opt.verbose = args.has("--verbose");
  opt.diagnose = args.has("--diagnose") || args.value("--diagnose-config").has_value();
  if (auto c = args.value("--diagnose-config")) opt.diagnoseConfig = *c;
  if (auto c = args.value("--configs")) opt.only = splitList(*c);
  opt.out = args.value("--out").value_or(args.value("-o").value_or(opt.out.string()));
  opt.data = args.value("--data").value_or(opt.data.string());
  opt.largeWorld = args.value("--large-world").value_or(opt.largeWorld.string());
  bench::applyGiBenchModeDefaults(opt);
  opt.width = args.integer("--width", opt.width, 8, 8192);
  opt.height = args.integer("--height", opt.height, 8, 8192);
  opt.samples = std::uint32_t(args.integer("--samples", int(opt.samples), 1, 1 << 20));
  opt.warmup = args.integer("--frames", opt.warmup, 1, 100000);
  opt.measured = args.integer("--measure", opt.measured, 1, 1000);
  opt.convergeCap = args.integer("--converge-cap", opt.convergeCap, 0, 100000);
  opt.rounds = args.integer("--rounds", opt.rounds, 1, 100);
  opt.settledFrames = args.integer("--settled-frames", opt.settledFrames, 0, 100000);
  opt.queryOffsetVoxels = args.number("--query-offset", opt.queryOffsetVoxels);
  const auto scenes = args.value("--scenes");
  opt.scenes = scenes ? splitList(*scenes) : bench::defaultGiBenchScenes(opt);
  const std::vector<std::string>& known = bench::benchSceneNames();
  for (const std::string& name : opt.scenes)
    if (std::find(known.begin(), known.end(), name.substr(0, name.find('@'))) == known.end())
      throw InputError(
          InputErrorKind::Usage, "command line",
          "unknown scene '" + name +
              "' (cornell-box, sponza, breakfast-room, courtyard, courtyard-sun, emissive-room, "
              "large-world, bunny)");
  const auto device = deviceFromArgs(args);
  if (!device)
    throw InputError(InputErrorKind::Usage, "command line", "bench gi needs a GPU (no --cpu)");
  opt.device = *device;
  opt.command = commandLine(argc, argv, 1);
  return bench::runGiBench(opt);
}

}  // namespace sdfstream::cli
