#include <cstdio>

#include "gpu/context.h"
#include "core/error.h"
#include "tools/args.h"
#include "tools/commands.h"
#include "tools/view_renderer.h"
#include "world/world_io.h"

namespace sdfstream::cli {

int runRender(int argc, char** argv) {
  Args args(argc, argv, 2, {"-o", "--camera", "--width", "--height", "--device", "--max-steps"},
            {"--help", "-h", "--cpu", "--validation"});
  if (args.has("--help") || args.has("-h")) {
    std::puts(
        "usage: sdfstream render WORLD -o IMAGE.png [options]\n"
        "\n"
        "Loads WORLD into a 128^3 cascade centred on the camera target and sphere-traces one\n"
        "primary ray per pixel on the GPU, then writes a preview-shaded PNG.\n"
        "\n"
        "  --camera px,py,pz,tx,ty,tz[,fov]  position, target (metres) and vertical fov (degrees);\n"
        "                                    default: frames the whole world\n"
        "  --width W --height H              image size (default 640 x 480)\n"
        "  --device NAME                     GPU index or part of its name (or SDFSTREAM_DEVICE)\n"
        "  --cpu                             trace with the CPU reference instead of Vulkan\n"
        "  --max-steps N                     sphere-tracing iteration cap (default 256)\n"
        "  --validation                      enable the Khronos validation layer");
    return 0;
  }
  if (args.positional().size() != 1 || !args.value("-o"))
    throw InputError(InputErrorKind::Usage, "command line",
                     "expected: sdfstream render WORLD -o IMAGE.png (see --help)");
  World world = readWorld(args.positional()[0]);
  Camera camera = defaultCamera(world);
  if (auto text = args.value("--camera")) {
    auto parsed = parseCamera(*text);
    if (!parsed)
      throw InputError(InputErrorKind::Usage, "command line",
                       "--camera expects px,py,pz,tx,ty,tz[,fov] with distinct points, got '" +
                           *text + "'");
    camera = *parsed;
  }
  int width = args.integer("--width", 640, 1, 8192);
  int height = args.integer("--height", 480, 1, 8192);
  TraceSettings settings;
  settings.maxSteps = std::uint32_t(args.integer("--max-steps", 256, 1, 100000));

  std::unique_ptr<gpu::Context> context = gpuContextFromArgs(args);
  ViewRenderer renderer(world, context.get(), settings);
  ViewResult r = renderer.render(camera, width, height);
  writePng(*args.value("-o"), r.image);
  std::printf("rendered %s (%dx%d) on %s: camera %s, %u bricks resident, %zu/%zu rays hit, "
              "trace %.2f ms (%.2f MRays/s)\n",
              args.value("-o")->c_str(), width, height,
              context ? context->deviceName().c_str() : "CPU reference", formatCamera(camera).c_str(),
              r.residentBricks, r.hits, r.rays, r.traceMilliseconds,
              r.rays / (r.traceMilliseconds * 1e3));
  return 0;
}

}  // namespace sdfstream::cli
