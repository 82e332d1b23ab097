// sdfstream fly: parses the fly-through's flags; the flight itself is demo/fly.h.
#include <algorithm>
#include <cstdio>

#include "core/error.h"
#include "demo/fly.h"
#include "tools/args.h"
#include "tools/commands.h"
#include "tools/render_args.h"

namespace sdfstream::cli {

int runFly(int argc, char** argv) {
  Args args(argc, argv, 2,
            renderValueOptions({"-o", "--path", "--speed", "--frames", "--width", "--height",
                                "--image-every", "--cascades", "--atlas-mib", "--upload-mib",
                                "--device", "--loader-threads", "--objects", "--sun-orbit",
                                "--sun-sweep", "--metrics-every"}),
            {"--help", "-h", "--cpu", "--no-pacing", "--layers", "--loop"});
  if (args.has("--help") || args.has("-h")) {
    std::printf(
        "usage: sdfstream fly WORLD -o DIR [options]\n"
        "\n"
        "Flies a camera over a world pack (headless), streaming tiles into camera-centred\n"
        "cascades without waiting on disk, and updates the GI (light cache + one probe volume\n"
        "per cascade) on the streamed stack every frame. Frames are shaded with direct +\n"
        "indirect light; scripted moving objects (--objects) move every frame and the GI sees\n"
        "them. Writes DIR/frames/frame-NNNN.png, DIR/metrics.csv, DIR/gi.csv (GI pass times and\n"
        "object counts per frame), DIR/summary.md, DIR/residency.png and DIR/bytes.png.\n"
        "\n"
        "  --path FILE        waypoints, one 'x y z' per line (default: a route across the world)\n"
        "  --speed M/S        camera speed (default 80 m/s, a fast fly-over)\n"
        "  --no-pacing        run frames back to back instead of at 30 per wall-clock second\n"
        "  --loop             fly back and forth along the path (long runs; default: stop at\n"
        "                     its end)\n"
        "  --sun-orbit DEG    turn the sun about the vertical by DEG degrees per frame (a\n"
        "                     moving sun: every frame is a light change; the light cache\n"
        "                     relights within --relight-pages, the longest out of date first;\n"
        "                     up to 1 degree a frame is a drift that wakes no probe)\n"
        "  --sun-sweep E0:E1  day to dusk: move the sun from E0 to E1 degrees of elevation over\n"
        "                     the run (azimuth kept), reddening and dimming it and the sky as\n"
        "                     it sets (demo/time_of_day.h); e.g. 35:3\n"
        "  --metrics-every K  keep the per-frame metrics of every K-th frame (default 1; long\n"
        "                     runs keep memory flat with 1000)\n"
        "  --frames N         frames at 30 per second of path time (default 300)\n"
        "  --width W --height H   frame size (default 320 x 180)\n"
        "  --image-every K    write every K-th frame as PNG (default frames/6)\n"
        "  --layers           also write frame-NNNN-direct.png and frame-NNNN-indirect.png\n"
        "                     (direct light only; indirect light only, 2 stops brighter: the\n"
        "                     objects' indirect shadows are easiest to see there)\n"
        "  --cascades N       cascades (default 6, at most the pack's LOD count)\n"
        "  --atlas-mib N      shared brick atlas budget (default 96)\n"
        "  --upload-mib N     brick bytes uploaded per frame at most (default 16)\n"
        "  --loader-threads N tile loader threads (default 2)\n"
        "  --objects N        scripted moving objects spread along the path (default 150, 0 =\n"
        "                     none; boxes and spheres of 1-4 m, every 6th 8-14 m, hovering in\n"
        "                     circles, falling and driving loops on the ground beside the\n"
        "                     path; Vulkan only). They cast direct and indirect shadows.\n"
        "  --gi-frames N                     GI frames at the start of the path before the flight\n"
        "                                    (default 0; they stream too, outside metrics.csv)\n"
        "%s"
        "  --device NAME | --cpu   GPU choice, or trace with the CPU reference (direct light "
        "only)\n",
        kRenderHelp);
    return 0;
  }
  if (args.positional().size() != 1 || !args.value("-o"))
    throw InputError(InputErrorKind::Usage, "command line",
                     "expected: sdfstream fly WORLD -o DIR (see --help)");
  FlyOptions o;
  o.world = args.positional()[0];
  o.out = *args.value("-o");
  if (auto path = args.value("--path")) o.path = *path;
  o.frames = args.integer("--frames", o.frames, 1, 100000);
  o.speed = args.number("--speed", o.speed);
  o.width = args.integer("--width", o.width, 16, 4096);
  o.height = args.integer("--height", o.height, 16, 4096);
  o.imageEvery = args.integer("--image-every", std::max(1, o.frames / 6), 1, 100000);
  o.pacing = !args.has("--no-pacing");
  o.loop = args.has("--loop");
  o.sunDegreesPerFrame = args.number("--sun-orbit", 0.0);
  if (auto sweep = args.value("--sun-sweep")) {
    double e0 = 0.0, e1 = 0.0;
    char tail = 0;
    if (std::sscanf(sweep->c_str(), "%lf:%lf%c", &e0, &e1, &tail) != 2 || !(e0 >= -10.0) ||
        !(e0 <= 90.0) || !(e1 >= -10.0) || !(e1 <= 90.0))
      throw InputError(InputErrorKind::Usage, "command line",
                       "--sun-sweep expects E0:E1, two elevations in degrees within [-10, 90], "
                       "got '" +
                           *sweep + "'");
    o.sunSweep = glm::dvec2(e0, e1);
  }
  o.metricsEvery = args.integer("--metrics-every", 1, 1, 1 << 30);
  o.layers = args.has("--layers");
  o.cascades = args.integer("--cascades", o.cascades, 1, 8);
  o.atlasMiB = args.number("--atlas-mib", o.atlasMiB);
  o.uploadMiB = args.number("--upload-mib", o.uploadMiB);
  o.loaderThreads = args.integer("--loader-threads", o.loaderThreads, 1, 64);
  const bool cpu = args.has("--cpu");
  o.render = renderOptionsFromArgs(args, cpu, 0, kProbeBudgetOfDevice, kRelightBudgetOfDevice);
  o.warmupGiFrames = o.render.giFrames;  // 0 unless --gi-frames is given
  o.objects = std::uint32_t(args.integer("--objects", cpu ? 0 : 150, 0, 100000));
  if (cpu && o.objects > 0)
    throw InputError(
        InputErrorKind::Usage, "command line",
        "--objects needs Vulkan (the CPU reference has no moving objects); drop --cpu");
  o.device = deviceFromArgs(args);
  return sdfstream::runFly(o);
}

}  // namespace sdfstream::cli
