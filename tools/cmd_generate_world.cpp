// sdfstream generate-world: the large built-in world's layout (world/generate_world.h).
#include <cstdio>
#include <filesystem>

#include "core/error.h"
#include "tools/args.h"
#include "tools/commands.h"
#include "world/generate_world.h"

namespace sdfstream::cli {

int runGenerateWorld(int argc, char** argv) {
  Args args(argc, argv, 2, {"-o", "--size-km", "--seed", "--map", "--height-scale"},
            {"--help", "-h", "--no-furniture"});
  if (args.has("--help") || args.has("-h")) {
    std::puts(
        "usage: sdfstream generate-world -o DIR [--size-km 4] [--seed N] [--map altitude]\n"
        "                                [--height-scale 120] [--no-furniture]\n"
        "\n"
        "Writes DIR/layout.json: a SIZE x SIZE km terrain from a trigger-rally-data heightmap\n"
        "(extracted from its data.zip into DIR/terrain/, stretched to span SIZE km) with real\n"
        "assets scattered on it at terrain height: glmark2-data's bunny, assimp-testmodels'\n"
        "2CylinderEngine and BoxTextured, and sweethome3d-furniture's CC0 models (their OBJ files\n"
        "extracted into DIR/assets/) when that package is installed. Other assets are referenced\n"
        "by absolute path. The same seed gives the same file.");
    return 0;
  }
  using Kind = InputErrorKind;
  if (!args.value("-o") || !args.positional().empty())
    throw InputError(Kind::Usage, "command line", "expected: sdfstream generate-world -o DIR");
  GenerateWorldOptions o;
  o.dir = std::filesystem::absolute(*args.value("-o"));
  o.sizeKm = args.number("--size-km", o.sizeKm);
  if (!(o.sizeKm > 0.0) || o.sizeKm > 1000.0)
    throw InputError(Kind::Usage, "command line", "--size-km must be in (0, 1000]");
  o.heightScale = args.number("--height-scale", o.heightScale);
  if (!(o.heightScale >= 0.0))
    throw InputError(Kind::Usage, "command line", "--height-scale must be >= 0");
  o.seed = args.integer("--seed", o.seed, 0, 1 << 30);
  o.map = args.value("--map").value_or(o.map);
  o.furniture = !args.has("--no-furniture");

  const GeneratedWorld g = generateWorld(o);
  if (!g.note.empty()) std::printf("%s\n", g.note.c_str());
  std::printf(
      "wrote %s\n  terrain  %s (%dx%d px) stretched from %.0f m to %.3f m per pixel so it spans "
      "%.1f x %.1f km, heights 0..%.0f m\n  assets   %d placements of %zu assets%s\n"
      "import it with:\n  sdfstream import %s -o WORLD --voxel 1 --lods 4\n",
      g.layout.c_str(), o.map.c_str(), g.widthPixels, g.heightPixels, g.sourceMetresPerPixel,
      g.metresPerPixel, o.sizeKm, g.metresPerPixel * (g.heightPixels - 1) / 1000.0, o.heightScale,
      g.placements, g.assets,
      g.furniture ? " (incl. sweethome3d-furniture CC0)" : " (sweethome3d-furniture not installed)",
      g.layout.c_str());
  return 0;
}

}  // namespace sdfstream::cli
