// sdfstream demo: parses the demo's flags; the demo itself is demo/demo_app.h.
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>

#include "core/error.h"
#include "demo/demo_app.h"
#include "tools/args.h"
#include "tools/commands.h"
#include "tools/render_args.h"

namespace fs = std::filesystem;

namespace sdfstream::cli {

int runDemo(int argc, char** argv) {
  Args args(argc, argv, 2,
            renderValueOptions(
                {"-o", "--scene", "--device", "--width", "--height", "--cornell", "--objects"}),
            {"--help", "-h", "--cpu"});
  if (args.has("--help") || args.has("-h")) {
    std::printf(
        "usage: sdfstream demo [-o DIR] [--scene LAYOUT.json] [options]\n"
        "\n"
        "Imports the built-in scene (Debian's glmark2 bunny and assimp test models on a ground\n"
        "slab between a red and a green wall, demo/default_scene.json), converges the GI probes\n"
        "and renders three views lit by a sun and a gradient sky, plus the Cornell box when\n"
        "../shared/data/cornell-box exists. Per view NAME: DIR/view-NAME.png (direct + indirect\n"
        "light), view-NAME-direct.png (direct only) and view-NAME-indirect.png (indirect only);\n"
        "then DIR/world/ and DIR/report.md (default DIR: out/demo). With moving objects (GPU\n"
        "only), a fourth view 'objects' repeats 'front' after a few GI frames with three scripted\n"
        "objects moving through the scene: compare view-objects-indirect.png with\n"
        "view-front-indirect.png for their indirect shadows.\n"
        "\n"
        "  --width W --height H              image size (default 640 x 480)\n"
        "  --objects on|off                  the objects view (default on; off with --cpu)\n"
        "  --cornell FILE|off                the Cornell box GLB (default ../shared/data/\n"
        "                                    cornell-box/CornellBox-Original.glb, or under\n"
        "                                    $SDFSTREAM_SHARED_DATA); off skips it\n"
        "%s%s"
        "  --device NAME | --cpu             GPU choice, or the CPU reference (direct light "
        "only)\n",
        kStillGiFramesHelp, kRenderHelp);
    return 0;
  }
  DemoOptions o;
  o.out = args.value("-o").value_or(o.out.string());
  o.scene = args.value("--scene").value_or("");
  o.width = args.integer("--width", o.width, 16, 4096);
  o.height = args.integer("--height", o.height, 16, 4096);
  const bool cpu = args.has("--cpu");
  o.render = renderOptionsFromArgs(args, cpu, 24);
  const std::string objects = args.value("--objects").value_or(cpu ? "off" : "on");
  if (objects != "on" && objects != "off")
    throw InputError(InputErrorKind::Usage, "command line",
                     "--objects expects on or off, got '" + objects + "'");
  if (objects == "on" && cpu)
    throw InputError(InputErrorKind::Usage, "command line",
                     "--objects on needs Vulkan (the CPU reference has no moving objects)");
  o.objects = objects == "on";
  const char* dataEnv = std::getenv("SDFSTREAM_SHARED_DATA");
  if (args.value("--cornell") != "off")
    o.cornell = args.value("--cornell")
                    .value_or((fs::path(dataEnv ? dataEnv : "../shared/data") / "cornell-box" /
                               "CornellBox-Original.glb")
                                  .string());
  if (args.value("--exposure")) o.cornellExposureStops = o.render.exposureStops;
  o.device = deviceFromArgs(args);
  return sdfstream::runDemo(o);
}

}  // namespace sdfstream::cli
