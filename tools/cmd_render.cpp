#include <cstdio>
#include <filesystem>

#include "core/error.h"
#include "demo/pack_lights.h"
#include "demo/view_renderer.h"
#include "gpu/context.h"
#include "tools/args.h"
#include "tools/commands.h"
#include "tools/render_args.h"
#include "world/world_io.h"

namespace fs = std::filesystem;

namespace sdfstream::cli {

int runRender(int argc, char** argv) {
  Args args(
      argc, argv, 2,
      renderValueOptions({"-o", "--camera", "--width", "--height", "--device", "--max-steps"}),
      {"--help", "-h", "--cpu", "--validation", "--layers"});
  if (args.has("--help") || args.has("-h")) {
    std::printf(
        "usage: sdfstream render WORLD -o IMAGE.png [options]\n"
        "\n"
        "Loads WORLD into a 128^3 cascade centred on the camera target, converges the GI probes\n"
        "on it (camera fixed), traces one primary ray per pixel on the GPU and writes the view\n"
        "shaded with direct + indirect light: emission + albedo/pi (E_direct + E_indirect),\n"
        "exposure, ACES filmic tone map, sRGB. Misses show the sky.\n"
        "\n"
        "  --camera px,py,pz,tx,ty,tz[,fov]  position, target (metres) and vertical fov "
        "(degrees);\n"
        "                                    default: frames the whole world\n"
        "  --width W --height H              image size (default 640 x 480)\n"
        "  --layers                          also write IMAGE-direct.png and IMAGE-indirect.png\n"
        "                                    (direct light only; indirect light only)\n"
        "%s%s"
        "  --device NAME                     GPU index or part of its name (or SDFSTREAM_DEVICE)\n"
        "  --cpu                             trace with the CPU reference instead of Vulkan\n"
        "                                    (direct light only)\n"
        "  --max-steps N                     sphere-tracing iteration cap (default 256)\n"
        "  --validation                      enable the Khronos validation layer\n",
        kStillGiFramesHelp, kRenderHelp);
    return 0;
  }
  if (args.positional().size() != 1 || !args.value("-o"))
    throw InputError(InputErrorKind::Usage, "command line",
                     "expected: sdfstream render WORLD -o IMAGE.png (see --help)");
  RenderOptions options = renderOptionsFromArgs(args, args.has("--cpu"), 24);
  World world = readWorld(args.positional()[0]);
  usePackLights(options, args.positional()[0]);
  Camera camera = defaultCamera(world);
  if (auto text = args.value("--camera")) {
    auto parsed = parseCamera(*text);
    if (!parsed)
      throw InputError(
          InputErrorKind::Usage, "command line",
          "--camera expects px,py,pz,tx,ty,tz[,fov] with distinct points, got '" + *text + "'");
    camera = *parsed;
  }
  int width = args.integer("--width", 640, 1, 8192);
  int height = args.integer("--height", 480, 1, 8192);
  TraceSettings settings;
  settings.maxSteps = std::uint32_t(args.integer("--max-steps", 256, 1, 100000));

  std::unique_ptr<gpu::Context> context = gpuContextFromArgs(args);
  ViewRenderer renderer(world, context.get(), options, settings);
  ViewResult r = renderer.render(camera, width, height);
  const fs::path out = *args.value("-o");
  writePng(out, r.image);
  if (args.has("--layers")) {
    const fs::path stem = out.parent_path() / out.stem();
    writePng(stem.string() + "-direct.png", r.directImage);
    writePng(stem.string() + "-indirect.png", r.indirectImage);
  }
  double probeMs = 0.0;
  for (double ms : r.probeMilliseconds) probeMs += ms;
  std::printf(
      "rendered %s (%dx%d) on %s: camera %s, %u bricks resident, %zu/%zu rays hit, "
      "shade %.2f ms (%.2f MRays/s)",
      out.c_str(), width, height, context ? context->deviceName().c_str() : "CPU reference",
      formatCamera(camera).c_str(), r.residentBricks, r.hits, r.rays, r.shadeMilliseconds,
      r.rays / (r.shadeMilliseconds * 1e3));
  if (options.gi)
    std::printf(
        ", GI %zu frames (converged after %d): probes %.1f ms/frame, light cache %.1f ms, "
        "irradiance queries %.1f ms",
        r.probeMilliseconds.size(), r.framesToConverge,
        r.probeMilliseconds.empty() ? 0.0 : probeMs / double(r.probeMilliseconds.size()),
        r.lightMilliseconds, r.sampleMilliseconds);
  std::printf("\n");
  if (r.nonFinite) std::printf("warning: %zu pixels had non-finite radiance\n", r.nonFinite);
  return 0;
}

}  // namespace sdfstream::cli
