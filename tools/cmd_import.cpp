#include <chrono>
#include <cstdio>

#include "core/error.h"
#include "tools/args.h"
#include "tools/commands.h"
#include "world/import.h"
#include "world/world_io.h"

namespace sdfstream::cli {

int runImport(int argc, char** argv) {
  Args args(argc, argv, 2, {"-o", "--voxel", "--max-memory-gib"}, {"--help", "-h"});
  if (args.has("--help") || args.has("-h")) {
    std::puts(
        "usage: sdfstream import INPUT -o WORLD [--voxel SIZE] [--max-memory-gib N]\n"
        "\n"
        "INPUT is a glTF 2.0 scene (.gltf/.glb), an OpenVDB level set (.vdb), an OBJ mesh, or a\n"
        "layout (.json) placing several of them. WORLD is written atomically: a failed import\n"
        "leaves no directory behind and an existing WORLD untouched.\n"
        "\n"
        "  --voxel SIZE         voxel edge in metres (default: the .vdb grid's own; for meshes the\n"
        "                       largest scene extent / 112, so the scene fits one 128^3 cascade)\n"
        "  --max-memory-gib N   refuse voxel sizes whose estimated narrow band exceeds N GiB (8)");
    return 0;
  }
  if (args.positional().size() != 1 || !args.value("-o"))
    throw InputError(InputErrorKind::Usage, "command line",
                     "expected: sdfstream import INPUT -o WORLD (see --help)");
  ImportOptions options;
  options.voxelSize = args.number("--voxel", 0.0);
  if (options.voxelSize < 0.0)
    throw InputError(InputErrorKind::Usage, "command line", "--voxel must be positive");
  options.limits.maxBytes =
      std::size_t(args.number("--max-memory-gib", 8.0) * double(1ull << 30));

  auto start = std::chrono::steady_clock::now();
  World world = importScene(args.positional()[0], options);
  double importSeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  writeWorld(world, *args.value("-o"));
  glm::dvec3 lo = world.worldMin(), hi = world.worldMax();
  std::printf("imported %s: %zu bricks, voxel %.4g m, bounds (%.3f %.3f %.3f)..(%.3f %.3f %.3f), %.2f s\n",
              args.positional()[0].c_str(), world.bricks.size(), world.voxelSize, lo.x, lo.y,
              lo.z, hi.x, hi.y, hi.z, importSeconds);
  return 0;
}

}  // namespace sdfstream::cli
