#include "world/generate_world.h"

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <fstream>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/atomic_dir.h"
#include "core/error.h"
#include "core/split_mix_rng.h"
#include "world/asset_proxy.h"
#include "world/heightfield_source.h"
#include "world/obj_import.h"
#include "world/world_plan.h"
#include "world/zip_reader.h"

namespace sdfstream {
namespace {

namespace fs = std::filesystem;
using Kind = InputErrorKind;

const fs::path kTriggerData = "/usr/share/games/trigger-rally/data.zip";
const fs::path kFurniture = "/usr/share/sweethome3d/furniture/BlendSwap-CC-0.sh3f";
const fs::path kScopia = "/usr/share/sweethome3d/furniture/Scopia.sh3f";  // CC-BY 3.0
constexpr double kTriggerMetresPerPixel = 5.0;                            // shared/data/README.md
constexpr const char* kCredits =
    ". Models: Sweet Home 3D furniture (Debian sweethome3d-furniture): Scopia Visual Interfaces "
    "Systems (CC-BY 3.0) and BlendSwap contributors (CC0); terrain: Trigger Rally (GPL-2+).";

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

// Every member under `folder` (e.g. "scopia/pine/": the OBJ, its MTL and textures) into `to`.
void extractFolder(const fs::path& zip, const std::vector<ZipMember>& members,
                   const std::string& folder, const fs::path& to) {
  bool any = false;
  for (const ZipMember& m : members)
    if (m.name.size() > folder.size() && m.name.compare(0, folder.size(), folder) == 0 &&
        m.name.back() != '/' && m.name.find("..") == std::string::npos) {
      writeBytes(to / m.name.substr(folder.size()), readZipMember(zip, m));
      any = true;
    }
  if (!any) throw InputError(Kind::MissingData, zip.string(), "has no folder " + folder);
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
    const fs::path folder = dir / "assets" / p.name;
    extractFolder(kFurniture, members, "blendswap-cc-0/" + std::string(p.name) + "/", folder);
    kinds.push_back({folder / (std::string(p.name) + ".obj"), p.count, p.minSize, p.maxSize});
  }
  return kinds;
}

// One placement of a model resting on the ground: on the lowest ground under its footprint,
// sunk a little so no edge floats, or on `floor` where that is higher (things inside the hall).
nlohmann::json restingPlacement(const Heightfield& field, glm::dvec2 at, double size, double yaw,
                                double floor = -1e300) {
  double ground = field.heightAt(at.x, at.y);
  for (int k = 0; k < 8; ++k) {
    const double a = k * M_PI / 4;
    ground = std::min(
        ground, field.heightAt(at.x + 0.5 * size * std::cos(a), at.y + 0.5 * size * std::sin(a)));
  }
  const double y = floor > ground ? floor : ground - 0.05 * size;
  return {{"translation", {at.x, y, at.y}},
          {"rotation", {0.0, std::sin(yaw / 2), 0.0, std::cos(yaw / 2)}},
          {"scale", size}};
}

nlohmann::json instanceEntry(const fs::path& file, nlohmann::json placements) {
  // fitSize 1 with scale s: each placement's largest extent is s metres.
  return {{"file", file.string()},
          {"fitSize", 1.0},
          {"onGround", true},
          {"placements", std::move(placements)}};
}

// The layout's "instances": each kind's placements at random positions, sizes and yaws, resting
// on the terrain and outside the planned settlements. Counts the placements into *placed.
nlohmann::json scatter(const std::vector<AssetKind>& kinds, const Heightfield& field,
                       const WorldPlan& plan, double size, int seed, int* placed) {
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
      if (occupiedAt(plan, {x, z}, 10.0)) continue;
      placements.push_back(restingPlacement(field, {x, z}, s, yaw));
      ++*placed;
    }
    if (!placements.empty()) instances.push_back(instanceEntry(kind.file, std::move(placements)));
  }
  return instances;
}

// The models behind each PlanAsset family: Sweet Home 3D's Scopia trees, cars and truck (CC-BY
// 3.0) and BlendSwap's CC0 container and forklift, extracted into dir/assets/NAME/ and written
// as flat-coloured stand-ins (world/asset_proxy.h). zAlong: the model's longer horizontal side
// runs along z, so a yaw meant for +x gets a quarter turn more.
struct PlanModel {
  fs::path file;
  bool zAlong = false;
  nlohmann::json placements = nlohmann::json::array();  // filled by planInstances
};

std::vector<std::vector<PlanModel>> planModels(const fs::path& dir) {
  struct Source {
    PlanAsset kind;
    const fs::path* zip;
    const char* folder;
    const char* name;
    std::size_t triangles;
  };
  const Source sources[] = {
      {PlanAsset::Conifer, &kScopia, "scopia/", "pine", 2500},
      {PlanAsset::Conifer, &kScopia, "scopia/", "cypress", 1500},
      {PlanAsset::Broadleaf, &kScopia, "scopia/", "copperBeech", 3000},
      {PlanAsset::Broadleaf, &kScopia, "scopia/", "sycamoreMaple", 3000},
      {PlanAsset::Broadleaf, &kScopia, "scopia/", "poplar", 2500},
      {PlanAsset::Bush, &kScopia, "scopia/", "bush", 800},
      {PlanAsset::Car, &kScopia, "scopia/", "suv", 3000},
      {PlanAsset::Car, &kScopia, "scopia/", "van", 3000},
      {PlanAsset::Car, &kScopia, "scopia/", "peugeot-308", 3000},
      {PlanAsset::Car, &kScopia, "scopia/", "renault-scenic", 3000},
      {PlanAsset::Truck, &kScopia, "scopia/", "truck", 4000},
      {PlanAsset::Container, &kFurniture, "blendswap-cc-0/", "shippingContainer", 4000},
      {PlanAsset::Forklift, &kFurniture, "blendswap-cc-0/", "forkLift", 4000},
  };
  std::vector<std::vector<PlanModel>> models(kPlanAssetCount);
  std::vector<ZipMember> scopia = listZip(kScopia), cc0 = listZip(kFurniture);
  for (const Source& s : sources) {
    const fs::path folder = dir / "assets" / s.name;
    extractFolder(*s.zip, s.zip == &kScopia ? scopia : cc0, std::string(s.folder) + s.name + "/",
                  folder);
    const TriangleScene scene = loadObj(folder / (std::string(s.name) + ".obj"));
    const fs::path proxy = folder / (std::string(s.name) + "-proxy.obj");
    writeProxyObj(scene, s.triangles, proxy);
    const glm::vec3 extent = scene.boundsMax() - scene.boundsMin();
    models[std::size_t(s.kind)].push_back({proxy, extent.z > extent.x});
  }
  return models;
}

// The plan's assets as layout instances: one entry per model, each placement picking one of its
// family's models at random.
nlohmann::json planInstances(const WorldPlan& plan, const Heightfield& field, const fs::path& dir,
                             int seed, int* placed) {
  std::vector<std::vector<PlanModel>> models = planModels(dir);
  SplitMixRng rng{std::uint64_t(seed) * 0xD1B54A32D192ED03ull + 3};
  for (const PlannedAsset& a : plan.assets) {
    auto& family = models[std::size_t(a.kind)];
    PlanModel& m = family[std::min(family.size() - 1, std::size_t(rng.uniform() * family.size()))];
    const double yaw = a.yaw + (m.zAlong ? M_PI / 2 : 0.0);
    m.placements.push_back(restingPlacement(field, a.at, a.size, yaw, a.floor));
    ++*placed;
  }
  nlohmann::json instances = nlohmann::json::array();
  for (auto& family : models)
    for (PlanModel& m : family)
      if (!m.placements.empty())
        instances.push_back(instanceEntry(m.file, std::move(m.placements)));
  return instances;
}

void writeLayout(const fs::path& file, const GenerateWorldOptions& o, const HeightfieldDesc& desc,
                 nlohmann::json instances, nlohmann::json boxes, bool furniture) {
  char command[256];
  std::snprintf(command, sizeof command,
                "sdfstream generate-world --size-km %g --seed %d --map %s --height-scale %g%s%s",
                o.sizeKm, o.seed, o.map.c_str(), o.heightScale, furniture ? "" : " --no-furniture",
                o.settlements ? "" : " --no-settlements");
  nlohmann::json layout = {{"comment", std::string(command) + kCredits},
                           {"terrain",
                            {{"heightmap", desc.png.string()},
                             {"metresPerPixel", desc.metresPerPixel},
                             {"heightScale", o.heightScale},
                             {"origin", {desc.origin.x, desc.origin.y, desc.origin.z}}}},
                           {"instances", std::move(instances)}};
  if (!boxes.empty()) layout["boxes"] = std::move(boxes);
  const std::string text = layout.dump(1) + "\n";
  writeFileAtomically(file, text.data(), text.size());
}

void writeFlight(const fs::path& file, const std::vector<glm::dvec3>& flight) {
  std::string text =
      "# The showcase flight of the generated world: over the forest, down the village street,\n"
      "# through the hall. sdfstream fly WORLD --path THIS_FILE\n";
  char line[96];
  for (const glm::dvec3& p : flight) {
    std::snprintf(line, sizeof line, "%.2f %.2f %.2f\n", p.x, p.y, p.z);
    text += line;
  }
  writeFileAtomically(file, text.data(), text.size());
}

}  // namespace

GeneratedWorld generateWorld(const GenerateWorldOptions& o) {
  if (!fs::exists(kTriggerData))
    throw InputError(Kind::MissingData, kTriggerData.string(),
                     "absent: install trigger-rally-data (scripts/setup does)");
  const double size = o.sizeKm * 1000.0;
  if (o.settlements && size < kMinSettlementWorldMetres)
    throw InputError(Kind::Usage, "command line",
                     "settlements need a world of at least " +
                         std::to_string(int(kMinSettlementWorldMetres / 100) / 10.0).substr(0, 3) +
                         " km (--size-km); give --no-settlements for a smaller one");
  if (o.settlements && !fs::exists(kScopia))
    throw InputError(Kind::MissingData, kScopia.string(),
                     "absent: install sweethome3d-furniture (scripts/setup does), or give "
                     "--no-settlements");
  fs::create_directories(o.dir);
  const fs::path heightmap =
      extract(kTriggerData, listZip(kTriggerData), "maps/" + o.map + "/h.png",
              o.dir / "terrain" / (o.map + "-h.png"));
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
  WorldPlan plan;
  if (o.settlements) plan = planWorld(field, size, std::uint64_t(o.seed));
  g.furniture = o.furniture && fs::exists(kFurniture);
  const std::vector<AssetKind> kinds = assetKinds(o.dir, g.furniture);
  g.assets = kinds.size();
  nlohmann::json instances = scatter(kinds, field, plan, size, o.seed, &g.placements);
  if (o.settlements) {
    for (nlohmann::json& entry : planInstances(plan, field, o.dir, o.seed, &g.placements))
      instances.push_back(std::move(entry));
    g.villages = plan.villages;
    g.houses = plan.houses;
    g.lamps = plan.lamps;
    g.boxes = plan.boxes.size();
    g.flight = o.dir / "flight.txt";
    writeFlight(g.flight, plan.flight);
  }
  g.layout = o.dir / "layout.json";
  writeLayout(g.layout, o, desc, std::move(instances), boxesJson(plan.boxes), g.furniture);
  return g;
}

}  // namespace sdfstream
