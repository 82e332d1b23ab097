#include <cstdio>
#include <filesystem>
#include <optional>

#include "core/error.h"
#include "demo/still_view.h"
#include "gpu/context.h"
#include "tools/args.h"
#include "tools/commands.h"
#include "tools/render_args.h"

namespace fs = std::filesystem;

namespace sdfstream::cli {

int runRender(int argc, char** argv) {
  Args args(argc, argv, 2,
            renderValueOptions({"-o", "--camera", "--width", "--height", "--device", "--max-steps",
                                "--cascades", "--atlas-mib", "--mesh", "--primary"}),
            {"--help", "-h", "--cpu", "--validation", "--layers"});
  if (args.has("--help") || args.has("-h")) {
    std::printf(
        "usage: sdfstream render WORLD -o IMAGE.png [options]\n"
        "\n"
        "Streams WORLD into the whole cascade stack, as the fly-through does: the cascades are\n"
        "centred on the camera when it is inside the world, else on its target, so any world\n"
        "can be framed. Converges the GI probes (camera fixed), traces one primary ray per pixel\n"
        "on the GPU and writes the view shaded with direct + indirect light: emission +\n"
        "albedo/pi (E_direct + E_indirect), exposure, ACES filmic tone map, sRGB. Misses show\n"
        "the sky.\n"
        "\n"
        "  --camera px,py,pz,tx,ty,tz[,fov]  position, target (metres) and vertical fov "
        "(degrees);\n"
        "                                    default: the whole world from above, across\n"
        "                                    its longer side, as close as it fits; a roofed\n"
        "                                    interior (mostly roof from there) is looked\n"
        "                                    into instead, from inside or from an open side\n"
        "  --width W --height H              image size (default 640 x 360)\n"
        "  --layers                          also write IMAGE-direct.png and IMAGE-indirect.png\n"
        "                                    (direct light only; indirect light only)\n"
        "  --cascades N                      cascades (default 8, at most the pack's LOD count)\n"
        "  --atlas-mib N                     shared brick atlas budget (default 96)\n"
        "%s%s%s"
        "  --device NAME                     GPU index or part of its name (or SDFSTREAM_DEVICE)\n"
        "  --cpu                             trace with the CPU reference instead of Vulkan\n"
        "                                    (direct light only)\n"
        "  --max-steps N                     sphere-tracing iteration cap (default 256)\n"
        "  --validation                      enable the Khronos validation layer\n",
        kPrimaryHelp, kStillGiFramesHelp, kRenderHelp);
    return 0;
  }
  if (args.positional().size() != 1 || !args.value("-o"))
    throw InputError(InputErrorKind::Usage, "command line",
                     "expected: sdfstream render WORLD -o IMAGE.png (see --help)");
  StreamedGiOptions world;
  world.world = args.positional()[0];
  world.cascades = args.integer("--cascades", 8, 1, 8);
  world.atlasMiB = args.number("--atlas-mib", world.atlasMiB);
  // Probe rays as the streamed commands choose them by device (a full update of every cascade
  // is ~2.5 M rays, 45 s a frame on lavapipe); every page is lit before the view, as it is still.
  world.render = renderOptionsFromArgs(args, args.has("--cpu"), 24, kProbeBudgetOfDevice);
  world.render.renderer.shading.trace.maxSteps =
      std::uint32_t(args.integer("--max-steps", 256, 1, 100000));
  std::optional<Camera> camera;
  if (auto text = args.value("--camera")) {
    camera = parseCamera(*text);
    if (!camera)
      throw InputError(
          InputErrorKind::Usage, "command line",
          "--camera expects px,py,pz,tx,ty,tz[,fov] with distinct points, got '" + *text + "'");
  }
  const int width = args.integer("--width", 640, 1, 8192);  // 16:9, as most engines' views
  const int height = args.integer("--height", 360, 1, 8192);

  world.primaryMesh = primaryMeshFromArgs(args, args.has("--cpu"));
  std::unique_ptr<gpu::Context> context = gpuContextFromArgs(args);
  StreamedGi streamed(world, context.get());
  const RenderOptions& options = streamed.render();
  if (!camera) camera = defaultStillCamera(streamed, double(width) / height);
  const ViewResult r = renderStill(streamed, *camera, width, height, options.giFrames);
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
      formatCamera(*camera).c_str(), r.residentBricks, r.hits, r.rays, r.shadeMilliseconds,
      r.rays / (r.shadeMilliseconds * 1e3));
  if (streamed.primaryMesh())
    std::printf(", raster primary %.2f ms (%zu triangles)", r.rasterMilliseconds,
                streamed.primaryMesh()->triangles.size());
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
