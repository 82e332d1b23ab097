#include "world/generate_world.h"

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <fstream>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/error.h"
#include "core/split_mix_rng.h"
#include "world/heightfield_source.h"
#include "world/zip_reader.h"

namespace sdfstream {
namespace {

namespace fs = std::filesystem;
using Kind = InputErrorKind;

const fs::path kTriggerData = "/usr/share/games/trigger-rally/data.zip";
const fs::path kFurniture = "/usr/share/sweethome3d/furniture/BlendSwap-CC-0.sh3f";
constexpr double kTriggerMetresPerPixel = 5.0;  // shared/data/README.md

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

// The heightmap stretched so its width spans `size` metres, centred on the origin.
HeightfieldDesc stretchedTerrain(const fs::path& heightmap, double size, double heightScale) {
  // Read the pixels once at a provisional scale to learn the image size, then stretch.
  HeightfieldDesc desc;
  desc.png = heightmap;
  desc.heightScale = heightScale;
  desc.metresPerPixel = 1.0;
  const int pixels = Heightfield::load(desc).width();
  desc.metresPerPixel = size / double(pixels - 1);
  desc.origin = glm::dvec3(-size / 2, 0.0, -size / 2);
  return desc;
}

// The packaged models, and the furniture's OBJ files extracted into dir/assets when installed.
std::vector<AssetKind> assetKinds(const fs::path& dir, bool furniture) {
  std::vector<AssetKind> kinds = {
      {"/usr/share/glmark2/models/bunny.obj", 16, 4.0, 10.0},
      {"/usr/share/assimp/models/glTF2/2CylinderEngine-glTF-Binary/2CylinderEngine.glb", 10, 6.0,
       12.0},
      {"/usr/share/assimp/models/glTF2/BoxTextured-glTF-Binary/BoxTextured.glb", 24, 2.0, 6.0},
  };
  if (!furniture) return kinds;
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
  return kinds;
}

// The layout's "instances": each kind's placements at random positions, sizes and yaws, resting
// on the terrain. Counts the placements into *placed.
nlohmann::json scatter(const std::vector<AssetKind>& kinds, const Heightfield& field, double size,
                       int seed, int* placed) {
  SplitMixRng rng{std::uint64_t(seed) * 0x2545F4914F6CDD1Dull + 1};
  nlohmann::json instances = nlohmann::json::array();
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
      ++*placed;
    }
    // fitSize 1 with scale s: each placement's largest extent is s metres.
    instances.push_back({{"file", kind.file.string()},
                         {"fitSize", 1.0},
                         {"onGround", true},
                         {"placements", placements}});
  }
  return instances;
}

void writeLayout(const fs::path& file, const GenerateWorldOptions& o, const HeightfieldDesc& desc,
                 nlohmann::json instances, bool furniture) {
  char command[256];
  std::snprintf(command, sizeof command,
                "sdfstream generate-world --size-km %g --seed %d --map %s --height-scale %g%s",
                o.sizeKm, o.seed, o.map.c_str(), o.heightScale, furniture ? "" : " --no-furniture");
  nlohmann::json layout = {{"comment", command},
                           {"terrain",
                            {{"heightmap", desc.png.string()},
                             {"metresPerPixel", desc.metresPerPixel},
                             {"heightScale", o.heightScale},
                             {"origin", {desc.origin.x, desc.origin.y, desc.origin.z}}}},
                           {"instances", std::move(instances)}};
  std::ofstream out(file, std::ios::binary);
  out << layout.dump(1) << "\n";
  if (!out) throw InputError(Kind::Io, file.string(), "cannot write");
}

}  // namespace

GeneratedWorld generateWorld(const GenerateWorldOptions& o) {
  if (!fs::exists(kTriggerData))
    throw InputError(Kind::MissingData, kTriggerData.string(),
                     "absent: install trigger-rally-data (scripts/setup does)");
  fs::create_directories(o.dir);
  const fs::path heightmap =
      extract(kTriggerData, listZip(kTriggerData), "maps/" + o.map + "/h.png",
              o.dir / "terrain" / (o.map + "-h.png"));
  const double size = o.sizeKm * 1000.0;
  const HeightfieldDesc desc = stretchedTerrain(heightmap, size, o.heightScale);
  const Heightfield field = Heightfield::load(desc);

  GeneratedWorld g;
  g.widthPixels = field.width();
  g.heightPixels = field.height();
  g.sourceMetresPerPixel = kTriggerMetresPerPixel;
  g.metresPerPixel = desc.metresPerPixel;
  if (field.height() != field.width()) {
    char note[160];
    std::snprintf(note, sizeof note, "note: heightmap is %dx%d; the world spans %.0f x %.0f m",
                  field.width(), field.height(), size, desc.metresPerPixel * (field.height() - 1));
    g.note = note;
  }
  g.furniture = o.furniture && fs::exists(kFurniture);
  const std::vector<AssetKind> kinds = assetKinds(o.dir, g.furniture);
  g.assets = kinds.size();
  nlohmann::json instances = scatter(kinds, field, size, o.seed, &g.placements);
  g.layout = o.dir / "layout.json";
  writeLayout(g.layout, o, desc, std::move(instances), g.furniture);
  return g;
}

}  // namespace sdfstream
