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
            {"--help", "-h", "--no-furniture", "--no-settlements"});
  if (args.has("--help") || args.has("-h")) {
    std::puts(
        "usage: sdfstream generate-world -o DIR [--size-km 4] [--seed N] [--map altitude]\n"
        "                                [--height-scale 120] [--no-furniture] [--no-settlements]\n"
        "\n"
        "Writes DIR/layout.json: a SIZE x SIZE km terrain from a trigger-rally-data heightmap\n"
        "(extracted from its data.zip into DIR/terrain/, stretched to span SIZE km) with:\n"
        "  - settlements: a main road across the world; villages of houses (boxes) along streets\n"
        "    with emissive street lamps, parked cars and garden trees; a hall with two doors to\n"
        "    fly through, lit by light strips; forests of Sweet Home 3D trees (sweethome3d-\n"
        "    furniture's Scopia models, CC-BY 3.0, simplified to flat-coloured stand-ins);\n"
        "    and DIR/flight.txt, the showcase route for 'sdfstream fly WORLD --path' (over the\n"
        "    forest, down the village street, through the hall). Needs --size-km >= 1.5;\n"
        "    --no-settlements leaves them out (the layout of earlier versions);\n"
        "  - scattered between them: glmark2-data's bunny, assimp-testmodels' 2CylinderEngine and\n"
        "    BoxTextured, and sweethome3d-furniture's CC0 models (--no-furniture: not those).\n"
        "Models are extracted into DIR/assets/; other assets are referenced by absolute path.\n"
        "The same seed gives the same files.");
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
  o.settlements = !args.has("--no-settlements");

  const GeneratedWorld g = generateWorld(o);
  if (!g.note.empty()) std::printf("%s\n", g.note.c_str());
  std::printf(
      "wrote %s\n  terrain  %s (%dx%d px) stretched from %.0f m to %.3f m per pixel so it spans "
      "%.1f x %.1f km, heights 0..%.0f m\n  assets   %d placements%s\n",
      g.layout.c_str(), o.map.c_str(), g.widthPixels, g.heightPixels, g.sourceMetresPerPixel,
      g.metresPerPixel, o.sizeKm, g.metresPerPixel * (g.heightPixels - 1) / 1000.0, o.heightScale,
      g.placements,
      g.furniture ? " (incl. sweethome3d-furniture CC0)"
                  : " (sweethome3d-furniture not installed)");
  if (!g.flight.empty())
    std::printf(
        "  built    %d villages, %d houses, %d street lamps, a hall (%zu boxes)\n"
        "  flight   %s\n",
        g.villages, g.houses, g.lamps, g.boxes, g.flight.c_str());
  std::printf(
      "import it with:\n  sdfstream import %s -o WORLD --voxel 1 --lods 6 --tile-voxels 256\n",
      g.layout.c_str());
  return 0;
}

}  // namespace sdfstream::cli
