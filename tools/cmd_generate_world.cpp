// sdfstream generate-world: a layout (world/scene_layout.h) for a kilometre world made of real
// Debian-packaged data: a trigger-rally-data heightmap as terrain, with the glmark2 bunny,
// assimp's 2CylinderEngine and BoxTextured, and (when installed) Sweet Home 3D's CC0 furniture
// scattered on it. Deterministic for a seed: positions come from a splitmix64 stream, not from
// <random>'s distributions (whose output differs between standard libraries).
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/error.h"
#include "tools/args.h"
#include "tools/commands.h"
#include "tools/zip_reader.h"
#include "world/heightfield_source.h"

namespace sdfstream::cli {
namespace {

namespace fs = std::filesystem;
using Kind = InputErrorKind;

const fs::path kTriggerData = "/usr/share/games/trigger-rally/data.zip";
const fs::path kFurniture = "/usr/share/sweethome3d/furniture/BlendSwap-CC-0.sh3f";
constexpr double kTriggerMetresPerPixel = 5.0;  // shared/data/README.md

struct Rng {
  std::uint64_t state;
  std::uint64_t next() {  // splitmix64
    std::uint64_t z = (state += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
  }
  double uniform(double lo, double hi) { return lo + (hi - lo) * double(next() >> 11) * 0x1p-53; }
};

// One kind of asset and how many to scatter, at what size (largest extent, metres).
struct AssetKind {
  fs::path file;
  int count;
  double minSize, maxSize;
};

void writeBytes(const fs::path& file, const std::vector<std::uint8_t>& bytes) {
  fs::create_directories(file.parent_path());
  std::ofstream out(file, std::ios::binary);
  out.write(reinterpret_cast<const char*>(bytes.data()), std::streamsize(bytes.size()));
  if (!out) throw InputError(Kind::Io, file.string(), "cannot write");
}

fs::path extract(const fs::path& zip, const std::vector<ZipMember>& members,
                 const std::string& name, const fs::path& to) {
  for (const ZipMember& m : members)
    if (m.name == name) {
      writeBytes(to, readZipMember(zip, m));
      return to;
    }
  throw InputError(Kind::MissingData, zip.string(), "has no member " + name);
}

}  // namespace

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
  if (!args.value("-o") || !args.positional().empty())
    throw InputError(Kind::Usage, "command line", "expected: sdfstream generate-world -o DIR");
  const fs::path dir = fs::absolute(*args.value("-o"));
  const double sizeKm = args.number("--size-km", 4.0);
  if (!(sizeKm > 0.0) || sizeKm > 1000.0)
    throw InputError(Kind::Usage, "command line", "--size-km must be in (0, 1000]");
  const double heightScale = args.number("--height-scale", 120.0);
  if (!(heightScale >= 0.0))
    throw InputError(Kind::Usage, "command line", "--height-scale must be >= 0");
  const int seed = args.integer("--seed", 1, 0, 1 << 30);
  const std::string map = args.value("--map").value_or("altitude");
  if (!fs::exists(kTriggerData))
    throw InputError(Kind::MissingData, kTriggerData.string(),
                     "absent: install trigger-rally-data (scripts/setup does)");

  fs::create_directories(dir);
  const fs::path heightmap = extract(kTriggerData, listZip(kTriggerData), "maps/" + map + "/h.png",
                                     dir / "terrain" / (map + "-h.png"));
  const double size = sizeKm * 1000.0;
  // Read the pixels once at a provisional scale to learn the image size, then stretch.
  HeightfieldDesc desc;
  desc.png = heightmap;
  desc.heightScale = heightScale;
  desc.metresPerPixel = 1.0;
  const int pixels = Heightfield::load(desc).width();
  desc.metresPerPixel = size / double(pixels - 1);
  desc.origin = glm::dvec3(-size / 2, 0.0, -size / 2);
  const Heightfield field = Heightfield::load(desc);
  if (field.height() != field.width())
    std::printf("note: heightmap is %dx%d; the world spans %.0f x %.0f m\n", field.width(),
                field.height(), size, desc.metresPerPixel * (field.height() - 1));

  std::vector<AssetKind> kinds = {
      {"/usr/share/glmark2/models/bunny.obj", 16, 4.0, 10.0},
      {"/usr/share/assimp/models/glTF2/2CylinderEngine-glTF-Binary/2CylinderEngine.glb", 10, 6.0,
       12.0},
      {"/usr/share/assimp/models/glTF2/BoxTextured-glTF-Binary/BoxTextured.glb", 24, 2.0, 6.0},
  };
  bool furniture = false;
  if (!args.has("--no-furniture") && fs::exists(kFurniture)) {
    const std::vector<ZipMember> members = listZip(kFurniture);
    struct Piece {
      const char* name;
      int count;
      double minSize, maxSize;
    };
    for (const Piece& p : {Piece{"shippingContainer", 10, 10.0, 14.0}, Piece{"rock2", 30, 2.0, 8.0},
                           Piece{"deer", 8, 2.0, 3.0}, Piece{"childHut", 6, 3.0, 5.0},
                           Piece{"outdoorLamp", 12, 3.5, 4.5}, Piece{"forkLift", 4, 3.0, 4.0}}) {
      const std::string member = "blendswap-cc-0/" + std::string(p.name) + "/" + p.name + ".obj";
      kinds.push_back(
          {extract(kFurniture, members, member, dir / "assets" / (std::string(p.name) + ".obj")),
           p.count, p.minSize, p.maxSize});
    }
    furniture = true;
  }

  Rng rng{std::uint64_t(seed) * 0x2545F4914F6CDD1Dull + 1};
  nlohmann::json instances = nlohmann::json::array();
  int placed = 0;
  const double margin = 0.05 * size;
  for (const AssetKind& kind : kinds) {
    if (!fs::exists(kind.file))
      throw InputError(Kind::MissingData, kind.file.string(),
                       "absent: install glmark2-data and assimp-testmodels (scripts/setup does)");
    nlohmann::json placements = nlohmann::json::array();
    for (int i = 0; i < kind.count; ++i) {
      const double x = rng.uniform(-size / 2 + margin, size / 2 - margin);
      const double z = rng.uniform(-size / 2 + margin, size / 2 - margin);
      const double s = rng.uniform(kind.minSize, kind.maxSize);
      const double yaw = rng.uniform(0.0, 2.0 * M_PI);
      // Rest on the lowest ground under the footprint, sunk a little so no edge floats.
      double ground = field.heightAt(x, z);
      for (int k = 0; k < 8; ++k) {
        const double a = k * M_PI / 4;
        ground =
            std::min(ground, field.heightAt(x + 0.5 * s * std::cos(a), z + 0.5 * s * std::sin(a)));
      }
      placements.push_back({{"translation", {x, ground - 0.05 * s, z}},
                            {"rotation", {0.0, std::sin(yaw / 2), 0.0, std::cos(yaw / 2)}},
                            {"scale", s}});
      ++placed;
    }
    // fitSize 1 with scale s: each placement's largest extent is s metres.
    instances.push_back({{"file", kind.file.string()},
                         {"fitSize", 1.0},
                         {"onGround", true},
                         {"placements", placements}});
  }
  char command[256];
  std::snprintf(command, sizeof command,
                "sdfstream generate-world --size-km %g --seed %d --map %s --height-scale %g%s",
                sizeKm, seed, map.c_str(), heightScale, furniture ? "" : " --no-furniture");
  nlohmann::json layout = {{"comment", command},
                           {"terrain",
                            {{"heightmap", heightmap.string()},
                             {"metresPerPixel", desc.metresPerPixel},
                             {"heightScale", heightScale},
                             {"origin", {desc.origin.x, desc.origin.y, desc.origin.z}}}},
                           {"instances", instances}};
  const fs::path file = dir / "layout.json";
  {
    std::ofstream out(file, std::ios::binary);
    out << layout.dump(1) << "\n";
    if (!out) throw InputError(Kind::Io, file.string(), "cannot write");
  }
  std::printf(
      "wrote %s\n  terrain  %s (%dx%d px) stretched from %.0f m to %.3f m per pixel so it spans "
      "%.1f x %.1f km, heights 0..%.0f m\n  assets   %d placements of %zu assets%s\n"
      "import it with:\n  sdfstream import %s -o WORLD --voxel 1 --lods 4\n",
      file.c_str(), map.c_str(), field.width(), field.height(), kTriggerMetresPerPixel,
      desc.metresPerPixel, sizeKm, desc.metresPerPixel * (field.height() - 1) / 1000.0, heightScale,
      placed, kinds.size(),
      furniture ? " (incl. sweethome3d-furniture CC0)" : " (sweethome3d-furniture not installed)",
      file.c_str());
  return 0;
}

}  // namespace sdfstream::cli
