// sdfstream view: parses the viewer's flags; the window and its frame loop are viewer/viewer.h.
#include <cstdio>
#include <string>

#include "core/error.h"
#include "gi/camera.h"
#include "tools/args.h"
#include "tools/commands.h"
#include "tools/render_args.h"
#include "viewer/view_input.h"
#include "viewer/viewer.h"

namespace sdfstream::cli {

int runView(int argc, char** argv) {
  Args args(argc, argv, 2,
            renderValueOptions({"-o", "--script", "--record", "--camera", "--speed", "--width",
                                "--height", "--scale", "--frames", "--cascades", "--atlas-mib",
                                "--upload-mib", "--loader-threads", "--objects", "--device",
                                "--mesh", "--primary"}),
            {"--help", "-h", "--headless", "--no-hud", "--no-vsync"});
  if (args.has("--help") || args.has("-h")) {
    std::printf(
        "usage: sdfstream view WORLD [options]\n"
        "\n"
        "Opens a window and flies a camera over a world pack: tiles stream into camera-centred\n"
        "cascades while you fly (a frame never waits on disk) and the GI (light cache + one\n"
        "probe volume per cascade) updates on the streamed stack every frame, as in `fly`.\n"
        "Needs a display (X11/Wayland; without one: `xvfb-run -a sdfstream view ...`, or\n"
        "--headless). A glTF, OBJ or layout is imported first: `sdfstream import SCENE -o WORLD`.\n"
        "\n"
        "Keys:\n%s"
        "\n"
        "  -o DIR             screenshots (F12) and script captures (default out/view)\n"
        "  --script FILE      scripted input instead of the keyboard: camera waypoints, held and\n"
        "                     pressed keys, mouse motion, captures (format: viewer/view_script.h;\n"
        "                     e.g. 'camera 0,2,8,0,1,0', 'hold W 30', 'press V', 'capture a')\n"
        "  --frames N         stop after N frames (default: when closed or the script ends)\n"
        "  --record DIR       write every presented frame to DIR/frame-NNNN.png\n"
        "  --camera px,py,pz,tx,ty,tz[,fov]   start there (default: render's default view)\n"
        "  --speed M/S        camera speed (default: the world's diagonal in 30 s)\n"
        "  --width W --height H   window size (default 1280 x 720)\n"
        "  --scale S          render resolution as a fraction of the window's (default 1 on a\n"
        "                     GPU, 0.25 on a CPU Vulkan device, which stays responsive so)\n"
        "  --headless         no window: render the same frames offscreen (captures, --record)\n"
        "  --no-hud           no text over the picture\n"
        "  --no-vsync         present without waiting for the display's refresh\n"
        "  --objects N        scripted moving objects along fly's route (default 0)\n"
        "  --cascades N       cascades (default 6, at most the pack's LOD count)\n"
        "  --atlas-mib N      shared brick atlas budget (default 96)\n"
        "  --upload-mib N     brick bytes uploaded per frame at most (default 16)\n"
        "  --loader-threads N tile loader threads (default 2)\n"
        "%s%s"
        "  --device NAME      GPU choice (index or part of its name; default: the best)\n",
        viewer::keyHelp().c_str(), kPrimaryHelp, kRenderHelp);
    return 0;
  }
  if (args.positional().size() != 1)
    throw InputError(InputErrorKind::Usage, "command line",
                     "expected: sdfstream view WORLD (see --help)");
  viewer::ViewOptions o;
  o.world.world = args.positional()[0];
  if (auto out = args.value("-o")) o.out = *out;
  if (auto script = args.value("--script")) o.script = *script;
  if (auto record = args.value("--record")) o.record = *record;
  if (auto text = args.value("--camera")) {
    o.camera = parseCamera(*text);
    if (!o.camera)
      throw InputError(InputErrorKind::Usage, "command line",
                       "--camera " + *text + ": expected px,py,pz,tx,ty,tz[,fov]");
  }
  o.speed = args.number("--speed", 0.0);
  o.width = args.integer("--width", o.width, 16, 8192);
  o.height = args.integer("--height", o.height, 16, 8192);
  o.renderScale = args.number("--scale", 0.0);
  if (o.renderScale < 0.0 || o.renderScale > 4.0)
    throw InputError(InputErrorKind::Usage, "command line", "--scale: expected 0 < S <= 4");
  o.frames = args.integer("--frames", 0, 0, 100000000);
  o.headless = args.has("--headless");
  o.hud = !args.has("--no-hud");
  o.vsync = !args.has("--no-vsync");
  o.objects = std::uint32_t(args.integer("--objects", 0, 0, 100000));
  o.world.cascades = args.integer("--cascades", o.world.cascades, 1, 8);
  o.world.atlasMiB = args.number("--atlas-mib", o.world.atlasMiB);
  o.world.uploadMiB = args.number("--upload-mib", o.world.uploadMiB);
  o.world.loaderThreads = args.integer("--loader-threads", o.world.loaderThreads, 1, 64);
  o.world.render =
      renderOptionsFromArgs(args, false, 0, kProbeBudgetOfDevice, kRelightBudgetOfDevice);
  o.world.primaryMesh = primaryMeshFromArgs(args, false);
  if (const auto device = deviceFromArgs(args)) o.device = *device;
  return viewer::runView(o);
}

}  // namespace sdfstream::cli
