// manifest.json of a world pack (pack.h, pack_format.h). Written with ordered_json so the key
// order is the order below; numbers are printed by nlohmann's shortest round-trip formatting.
//
//   {
//     "format": "sdfstream-pack", "version": 1,
//     "partition": {"voxelSize": v0, "lodCount": L, "tileVoxels": T, "tileSize": v0·T (metres,
//                   informational), "origin": [x, y, z]},
//     "bounds": {"min": [x, y, z], "max": [x, y, z]},
//     "source": "...", "materials": ["..."], "objectLibrary": [],
//     "lights": [{"type": "sun"|"point"|"spot", "position": [x, y, z], "direction": [x, y, z],
//                 "color": [r, g, b], "intensity": i, "range": r, "innerConeDegrees": a,
//                 "outerConeDegrees": b, "shadowSharpness": k, "castsShadows": true}, ...]
//                 (only when the sources have lights of their own: scene_lights.h's fields)
//     "tiles": [{"coord": [x, y, z], "file": "tiles/x_y_z.tile", "bytes": n,
//                "xxh3": "16 hex digits", "bricks": [per LOD]}, ...]   sorted (z, y, x),
//                                                                     one compact line each
//   }
#include <cmath>
#include <cstdlib>

#include <nlohmann/json.hpp>

#include "core/error.h"
#include "core/hash.h"
#include "world/pack_format.h"

namespace sdfstream::pack_format {
namespace {

using ordered = nlohmann::ordered_json;
using json = nlohmann::json;

ordered vec3(glm::dvec3 v) { return ordered::array({v.x, v.y, v.z}); }
ordered vec3(glm::ivec3 v) { return ordered::array({v.x, v.y, v.z}); }

const char* lightTypeName(SceneLight::Type t) {
  switch (t) {
    case SceneLight::Type::Sun: return "sun";
    case SceneLight::Type::Point: return "point";
    case SceneLight::Type::Spot: return "spot";
  }
  return "sun";
}

ordered lightJson(const SceneLight& l) {
  return {{"type", lightTypeName(l.type)},
          {"position", vec3(l.position)},
          {"direction", vec3(glm::dvec3(l.direction))},
          {"color", vec3(glm::dvec3(l.color))},
          {"intensity", l.intensity},
          {"range", l.range},
          {"innerConeDegrees", l.innerConeDegrees},
          {"outerConeDegrees", l.outerConeDegrees},
          {"shadowSharpness", l.shadowSharpness},
          {"castsShadows", l.castsShadows}};
}

// Reads typed values out of untrusted JSON; every error names the key path ("tiles[3].bytes").
class Reader {
 public:
  explicit Reader(std::string file) : file_(std::move(file)) {}

  [[noreturn]] void fail(const std::string& key, const std::string& what) const {
    throw InputError(InputErrorKind::Malformed, file_, "key '" + key + "': " + what);
  }
  const json& at(const json& object, const std::string& path, const char* key) const {
    if (!object.is_object()) fail(path, "expected an object");
    auto it = object.find(key);
    if (it == object.end()) fail(join(path, key), "missing");
    return *it;
  }
  static std::string join(const std::string& path, const char* key) {
    return path.empty() ? key : path + "." + key;
  }
  double number(const json& o, const std::string& path, const char* key) const {
    const json& v = at(o, path, key);
    if (!v.is_number()) fail(join(path, key), "expected a number");
    const double d = v.get<double>();
    if (!std::isfinite(d))
      throw InputError(InputErrorKind::NonFinite, file_, "key '" + join(path, key) + "'");
    return d;
  }
  std::uint64_t unsignedInt(const json& o, const std::string& path, const char* key,
                            std::uint64_t max) const {
    const json& v = at(o, path, key);
    if (!v.is_number_unsigned() && !(v.is_number_integer() && v.get<std::int64_t>() >= 0))
      fail(join(path, key), "expected a non-negative integer");
    const std::uint64_t u = v.get<std::uint64_t>();
    if (u > max) fail(join(path, key), "larger than " + std::to_string(max));
    return u;
  }
  std::string string(const json& o, const std::string& path, const char* key) const {
    const json& v = at(o, path, key);
    if (!v.is_string()) fail(join(path, key), "expected a string");
    return v.get<std::string>();
  }
  const json& array(const json& o, const std::string& path, const char* key) const {
    const json& v = at(o, path, key);
    if (!v.is_array()) fail(join(path, key), "expected an array");
    return v;
  }
  glm::dvec3 dvec3(const json& o, const std::string& path, const char* key) const {
    const json& v = array(o, path, key);
    const std::string name = join(path, key);
    if (v.size() != 3) fail(name, "expected 3 numbers");
    glm::dvec3 r;
    for (int a = 0; a < 3; ++a) {
      if (!v[a].is_number()) fail(name, "expected 3 numbers");
      r[a] = v[a].get<double>();
      if (!std::isfinite(r[a])) throw InputError(InputErrorKind::NonFinite, file_, name);
    }
    return r;
  }
  glm::ivec3 ivec3(const json& o, const std::string& path, const char* key) const {
    const json& v = array(o, path, key);
    const std::string name = join(path, key);
    if (v.size() != 3) fail(name, "expected 3 integers");
    glm::ivec3 r;
    for (int a = 0; a < 3; ++a) {
      if (!v[a].is_number_integer()) fail(name, "expected 3 integers");
      const std::int64_t i = v[a].get<std::int64_t>();
      if (i < INT32_MIN || i > INT32_MAX) fail(name, "out of range");
      r[a] = int(i);
    }
    return r;
  }

 private:
  std::string file_;
};

SceneLight readLight(const Reader& r, const json& o, const std::string& path) {
  SceneLight l;
  const std::string type = r.string(o, path, "type");
  if (type == "sun") l.type = SceneLight::Type::Sun;
  else if (type == "point") l.type = SceneLight::Type::Point;
  else if (type == "spot") l.type = SceneLight::Type::Spot;
  else r.fail(path + ".type", "expected sun, point or spot");
  l.position = r.dvec3(o, path, "position");
  l.direction = glm::vec3(r.dvec3(o, path, "direction"));
  if (glm::length(l.direction) < 1e-6f) r.fail(path + ".direction", "expected a non-zero vector");
  l.direction = glm::normalize(l.direction);
  l.color = glm::vec3(r.dvec3(o, path, "color"));
  l.intensity = float(r.number(o, path, "intensity"));
  l.range = float(r.number(o, path, "range"));
  l.innerConeDegrees = float(r.number(o, path, "innerConeDegrees"));
  l.outerConeDegrees = float(r.number(o, path, "outerConeDegrees"));
  l.shadowSharpness = float(r.number(o, path, "shadowSharpness"));
  const json& shadows = r.at(o, path, "castsShadows");
  if (!shadows.is_boolean()) r.fail(path + ".castsShadows", "expected true or false");
  l.castsShadows = shadows.get<bool>();
  if (l.color.r < 0 || l.color.g < 0 || l.color.b < 0 || l.intensity < 0 || l.range < 0 ||
      l.shadowSharpness < 0)
    r.fail(path, "colour, intensity, range and shadowSharpness must be >= 0");
  if (!(l.innerConeDegrees >= 0 && l.innerConeDegrees <= l.outerConeDegrees &&
        l.outerConeDegrees <= 90))
    r.fail(path, "expected 0 <= innerConeDegrees <= outerConeDegrees <= 90");
  return l;
}

std::vector<SceneLight> readLights(const Reader& r, const json& list) {
  if (list.size() > kMaxManifestLights)
    r.fail("lights", "more than " + std::to_string(kMaxManifestLights) + " lights");
  std::vector<SceneLight> lights;
  for (std::size_t i = 0; i < list.size(); ++i)
    lights.push_back(readLight(r, list[i], "lights[" + std::to_string(i) + "]"));
  return lights;
}

}  // namespace

std::string manifestText(const PackManifest& m) {
  ordered j;
  j["format"] = kManifestFormat;
  j["version"] = kManifestVersion;
  j["partition"] = {{"voxelSize", m.spec.voxelSize},
                    {"lodCount", m.spec.lodCount},
                    {"tileVoxels", m.spec.tileVoxels},
                    {"tileSize", m.spec.tileSizeMeters()},
                    {"origin", vec3(m.spec.origin)}};
  j["bounds"] = {{"min", vec3(m.boundsMin)}, {"max", vec3(m.boundsMax)}};
  j["source"] = m.source;
  j["materials"] = m.materials;
  j["objectLibrary"] = ordered::array();
  if (!m.lights.empty()) {
    j["lights"] = ordered::array();
    for (const SceneLight& l : m.lights) j["lights"].push_back(lightJson(l));
  }
  // One line per tile: a kilometre world has thousands, and line-wise diffs stay readable.
  std::string text = j.dump(2);
  text.resize(text.size() - 2);  // drop "\n}"
  text += ",\n  \"tiles\": [";
  for (std::size_t i = 0; i < m.tiles.size(); ++i) {
    const TileEntry& t = m.tiles[i];
    const ordered tile = {{"coord", vec3(t.coord)},
                          {"file", t.file},
                          {"bytes", t.bytes},
                          {"xxh3", toHex(t.checksum)},
                          {"bricks", t.bricksPerLod}};
    text += (i ? ",\n    " : "\n    ") + tile.dump();
  }
  text += m.tiles.empty() ? "]\n}\n" : "\n  ]\n}\n";
  return text;
}

PackManifest parseManifest(const std::string& text, const std::string& file) {
  const json j = json::parse(text, nullptr, /*allow_exceptions=*/false);
  if (j.is_discarded()) throw InputError(InputErrorKind::Malformed, file, "not valid JSON");
  if (!j.is_object()) throw InputError(InputErrorKind::Malformed, file, "not a JSON object");
  Reader r(file);
  if (r.string(j, "", "format") != kManifestFormat)
    throw InputError(InputErrorKind::Version, file, "not an sdfstream pack (key 'format')");
  const std::uint64_t version = r.unsignedInt(j, "", "version", UINT32_MAX);
  if (version != kManifestVersion)
    throw InputError(InputErrorKind::Version, file,
                     "pack version " + std::to_string(version) + " is not supported (expected " +
                         std::to_string(kManifestVersion) + ")");
  PackManifest m;
  const json& p = r.at(j, "", "partition");
  m.spec.voxelSize = r.number(p, "partition", "voxelSize");
  m.spec.lodCount = int(r.unsignedInt(p, "partition", "lodCount", PartitionSpec::kMaxLods));
  m.spec.tileVoxels = int(r.unsignedInt(p, "partition", "tileVoxels", INT32_MAX));
  m.spec.origin = r.dvec3(p, "partition", "origin");
  if (std::string problem = specProblem(m.spec); !problem.empty()) r.fail("partition", problem);
  const json& bounds = r.at(j, "", "bounds");
  m.boundsMin = r.dvec3(bounds, "bounds", "min");
  m.boundsMax = r.dvec3(bounds, "bounds", "max");
  m.source = r.string(j, "", "source");
  const json& materials = r.array(j, "", "materials");
  for (std::size_t i = 0; i < materials.size(); ++i) {
    if (!materials[i].is_string()) r.fail("materials[" + std::to_string(i) + "]", "not a string");
    m.materials.push_back(materials[i].get<std::string>());
  }
  r.array(j, "", "objectLibrary");
  if (j.contains("lights")) m.lights = readLights(r, r.array(j, "", "lights"));

  const json& tiles = r.array(j, "", "tiles");
  m.tiles.reserve(tiles.size());
  for (std::size_t i = 0; i < tiles.size(); ++i) {
    const std::string path = "tiles[" + std::to_string(i) + "]";
    const json& t = tiles[i];
    TileEntry e;
    e.coord = r.ivec3(t, path, "coord");
    if (!coordInRange(e.coord, m.spec)) r.fail(path + ".coord", "out of range");
    e.file = r.string(t, path, "file");
    if (e.file != tileFileName(e.coord))
      r.fail(path + ".file", "expected \"" + tileFileName(e.coord) + "\"");
    e.bytes = r.unsignedInt(t, path, "bytes", UINT64_MAX);
    const std::string hex = r.string(t, path, "xxh3");
    char* end = nullptr;
    e.checksum = std::strtoull(hex.c_str(), &end, 16);
    if (hex.size() != 16 || end != hex.c_str() + 16 || toHex(e.checksum) != hex)
      r.fail(path + ".xxh3", "expected 16 lower-case hex digits");
    const json& bricks = r.array(t, path, "bricks");
    if (bricks.size() != std::size_t(m.spec.lodCount))
      r.fail(path + ".bricks", "expected one count per LOD");
    for (int l = 0; l < m.spec.lodCount; ++l) {
      const std::uint64_t n = std::uint64_t(m.spec.tileBricks(l));
      if (!bricks[l].is_number_unsigned() || bricks[l].get<std::uint64_t>() > n * n * n)
        r.fail(path + ".bricks", "expected brick counts within the tile's slots");
      e.bricksPerLod.push_back(bricks[l].get<std::uint32_t>());
    }
    if (i > 0) {
      const glm::ivec3 a = m.tiles.back().coord;
      if (!brickCoordLess(a, e.coord)) r.fail(path + ".coord", "tiles not sorted or not unique");
    }
    m.tiles.push_back(std::move(e));
  }
  return m;
}

}  // namespace sdfstream::pack_format
