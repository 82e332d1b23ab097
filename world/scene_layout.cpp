#include "world/scene_layout.h"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <fstream>
#include <iterator>
#include <optional>
#include <string>
#include <vector>

#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/quaternion.hpp>
#include <nlohmann/json.hpp>

#include "core/error.h"
#include "core/printable.h"
#include "core/read_file.h"
#include "world/gltf_import.h"
#include "world/obj_import.h"

namespace sdfstream {
namespace {

using Json = nlohmann::json;
using Kind = InputErrorKind;

struct Reader {
  std::string file;

  // The key path holds the file's own keys, which may hold a newline: quoted printable so the
  // error stays one line.
  [[noreturn]] void fail(Kind kind, const std::string& key, const std::string& problem) const {
    throw InputError(kind, file, printable(key) + ": " + problem);
  }

  void onlyKeys(const Json& obj, const std::string& path,
                std::initializer_list<const char*> allowed) const {
    if (!obj.is_object()) fail(Kind::Malformed, path, "expected an object");
    // Not a structured binding: clang 14 (the fuzz build's compiler) cannot capture one.
    for (const auto& item : obj.items()) {
      const std::string& key = item.key();
      if (std::none_of(allowed.begin(), allowed.end(), [&](const char* a) { return key == a; }))
        fail(Kind::Malformed, path + "." + key, "unknown key");
    }
  }

  double number(const Json& v, const std::string& key) const {
    if (!v.is_number()) fail(Kind::Malformed, key, "expected a number");
    const double d = v.get<double>();
    if (!std::isfinite(d)) fail(Kind::NonFinite, key, "not a finite number");
    return d;
  }

  template <int N>
  glm::vec<N, double> numbers(const Json& obj, const std::string& path, const char* key,
                              glm::vec<N, double> fallback) const {
    auto it = obj.find(key);
    if (it == obj.end()) return fallback;
    const std::string k = path + "." + key;
    if (!it->is_array() || it->size() != N ||
        !std::all_of(it->begin(), it->end(), [](const Json& e) { return e.is_number(); }))
      fail(Kind::Malformed, k, "expected " + std::to_string(N) + " numbers");
    glm::vec<N, double> out;
    for (int i = 0; i < N; ++i) out[i] = number((*it)[std::size_t(i)], k);
    return out;
  }

  const Json* array(const Json& root, const char* key) const {
    auto it = root.find(key);
    if (it == root.end()) return nullptr;
    if (!it->is_array()) fail(Kind::Malformed, key, "expected an array");
    return &*it;
  }
};

TriangleScene makeBox(glm::vec3 lo, glm::vec3 hi, const Material& material) {
  TriangleScene box;
  for (int i = 0; i < 8; ++i)  // corner i: bit 0 → x, bit 1 → y, bit 2 → z
    box.positions.emplace_back(i & 1 ? hi.x : lo.x, i & 2 ? hi.y : lo.y, i & 4 ? hi.z : lo.z);
  box.uvs.assign(8, glm::vec2(0.0f));
  // Two counter-clockwise (seen from outside) triangles per face: -x, +x, -y, +y, -z, +z.
  static const unsigned faces[6][4] = {{0, 4, 6, 2}, {1, 3, 7, 5}, {0, 1, 5, 4},
                                       {2, 6, 7, 3}, {0, 2, 3, 1}, {4, 5, 7, 6}};
  for (const auto& f : faces) {
    box.triangles.emplace_back(f[0], f[1], f[2]);
    box.triangles.emplace_back(f[0], f[2], f[3]);
  }
  box.triangleMaterial.assign(12, 0);
  box.materials.push_back(material);
  return box;
}

// Reads the placement keys shared by "assets" entries and "placements" items.
LayoutPlacement readPlacement(const Reader& r, const Json& a, const std::string& path) {
  LayoutPlacement p;
  p.translation = r.numbers<3>(a, path, "translation", glm::dvec3(0.0));
  const glm::dvec4 q = r.numbers<4>(a, path, "rotation", glm::dvec4(0, 0, 0, 1));
  if (glm::length(q) < 1e-12) r.fail(Kind::Malformed, path + ".rotation", "zero quaternion");
  p.rotation = glm::normalize(glm::dquat(q.w, q.x, q.y, q.z));
  if (auto it = a.find("scale"); it != a.end())
    p.scale = it->is_number() ? glm::dvec3(r.number(*it, path + ".scale"))
                              : r.numbers<3>(a, path, "scale", p.scale);
  return p;
}

// The keys describing the asset itself (file, fitSize, onGround, name).
LayoutAsset readAsset(const Reader& r, const Json& a, const std::string& path,
                      const std::filesystem::path& dir) {
  LayoutAsset asset;
  asset.key = path;
  auto f = a.find("file");
  if (f == a.end() || !f->is_string() || f->get<std::string>().empty())
    r.fail(Kind::Malformed, path + ".file", "expected a file name");
  if (auto n = a.find("name"); n != a.end() && !n->is_string())
    r.fail(Kind::Malformed, path + ".name", "expected a string");
  if (auto it = a.find("fitSize"); it != a.end()) {
    asset.fitSize = r.number(*it, path + ".fitSize");
    if (*asset.fitSize <= 0.0) r.fail(Kind::Malformed, path + ".fitSize", "expected a size > 0");
  }
  if (auto it = a.find("onGround"); it != a.end()) {
    if (!it->is_boolean()) r.fail(Kind::Malformed, path + ".onGround", "expected true or false");
    asset.onGround = it->get<bool>();
  }
  asset.file = f->get<std::string>();
  if (asset.file.is_relative()) asset.file = dir / asset.file;
  std::error_code ec;
  if (!std::filesystem::exists(asset.file, ec))
    r.fail(Kind::MissingData, path + ".file", printable(asset.file.string()) + " does not exist");
  return asset;
}

HeightfieldDesc readTerrain(const Reader& r, const Json& t, const std::filesystem::path& dir) {
  const std::string path = "terrain";
  r.onlyKeys(t, path, {"heightmap", "metresPerPixel", "heightScale", "origin", "albedo", "name"});
  HeightfieldDesc desc;
  auto f = t.find("heightmap");
  if (f == t.end() || !f->is_string() || f->get<std::string>().empty())
    r.fail(Kind::Malformed, path + ".heightmap", "expected a file name");
  desc.png = f->get<std::string>();
  if (desc.png.is_relative()) desc.png = dir / desc.png;
  std::error_code ec;
  if (!std::filesystem::exists(desc.png, ec))
    r.fail(Kind::MissingData, path + ".heightmap",
           printable(desc.png.string()) + " does not exist");
  auto required = [&](const char* key) {
    auto it = t.find(key);
    if (it == t.end()) r.fail(Kind::Malformed, path + "." + key, "required");
    return r.number(*it, path + "." + key);
  };
  desc.metresPerPixel = required("metresPerPixel");
  if (desc.metresPerPixel <= 0.0)
    r.fail(Kind::Malformed, path + ".metresPerPixel", "expected a size > 0");
  desc.heightScale = required("heightScale");
  if (desc.heightScale < 0.0)
    r.fail(Kind::Malformed, path + ".heightScale", "expected a height >= 0");
  desc.origin = r.numbers<3>(t, path, "origin", glm::dvec3(0.0));
  desc.albedo = glm::vec3(r.numbers<3>(t, path, "albedo", glm::dvec3(desc.albedo)));
  return desc;
}

}  // namespace

// Appends `part` to `out` transformed by m (materials and textures re-indexed).
void appendTransformedGeometry(TriangleScene& out, const TriangleScene& part, const glm::dmat4& m,
                               std::uint32_t materialBase) {
  const auto vertexBase = std::uint32_t(out.positions.size());
  for (const glm::vec3& p : part.positions) out.positions.emplace_back(m * glm::dvec4(p, 1.0));
  out.uvs.insert(out.uvs.end(), part.uvs.begin(), part.uvs.end());
  out.uvs.resize(out.positions.size(), glm::vec2(0.0f));
  if (!part.uvs1.empty() || !out.uvs1.empty()) {  // the second set only where some part has one
    out.uvs1.resize(vertexBase, glm::vec2(0.0f));
    out.uvs1.insert(out.uvs1.end(), part.uvs1.begin(), part.uvs1.end());
    out.uvs1.resize(out.positions.size(), glm::vec2(0.0f));
  }
  for (const SceneLight& light : part.lights) out.lights.push_back(transformLight(light, m));
  const bool flip = glm::determinant(m) < 0.0;
  for (const glm::uvec3& t : part.triangles)
    out.triangles.push_back(glm::uvec3(vertexBase) + (flip ? glm::uvec3(t.x, t.z, t.y) : t));
  for (std::uint32_t mat : part.triangleMaterial)
    out.triangleMaterial.push_back(materialBase + mat);
}

void appendTransformed(TriangleScene& out, const TriangleScene& part, const glm::dmat4& m) {
  const auto materialBase = std::uint32_t(out.materials.size());
  const int textureBase = int(out.textures.size());
  appendTransformedGeometry(out, part, m, materialBase);
  for (Material mat : part.materials) {
    if (mat.baseColorTexture >= 0) mat.baseColorTexture += textureBase;
    if (mat.emissiveTexture >= 0) mat.emissiveTexture += textureBase;
    out.materials.push_back(std::move(mat));
  }
  out.textures.insert(out.textures.end(), part.textures.begin(), part.textures.end());
}

ParsedLayout parseLayout(const std::filesystem::path& jsonFile) {
  Reader r{jsonFile.string()};
  const std::string text = readWholeFile(jsonFile, r.file);
  Json root;
  try {
    root = Json::parse(text);
  } catch (const Json::parse_error& e) {
    std::string reason = e.what();
    if (auto colon = reason.find(": "); colon != std::string::npos) reason.erase(0, colon + 2);
    throw InputError(Kind::Malformed, r.file,
                     "invalid JSON at " + detail::jsonLineColumn(text, e.byte) + ": " + reason);
  } catch (const Json::exception& e) {
    // Not only parse_error: a number too large for a double ("1e999") is out_of_range (406).
    std::string reason = e.what();
    if (auto colon = reason.find("] "); colon != std::string::npos) reason.erase(0, colon + 2);
    throw InputError(Kind::Malformed, r.file, "invalid JSON: " + printable(reason));
  }
  if (!root.is_object()) throw InputError(Kind::Malformed, r.file, "top level is not an object");
  r.onlyKeys(root, "layout", {"assets", "instances", "boxes", "terrain", "comment"});
  const std::filesystem::path dir = jsonFile.parent_path();

  ParsedLayout layout;
  layout.file = r.file;
  layout.boxes.source = r.file;
  if (const Json* assets = r.array(root, "assets")) {
    for (std::size_t i = 0; i < assets->size(); ++i) {
      const Json& a = (*assets)[i];
      const std::string path = "assets[" + std::to_string(i) + "]";
      r.onlyKeys(a, path,
                 {"file", "translation", "rotation", "scale", "fitSize", "onGround", "name"});
      LayoutAsset asset = readAsset(r, a, path, dir);
      asset.placements.push_back(readPlacement(r, a, path));
      layout.assets.push_back(std::move(asset));
    }
  }
  if (const Json* instances = r.array(root, "instances")) {
    for (std::size_t i = 0; i < instances->size(); ++i) {
      const Json& a = (*instances)[i];
      const std::string path = "instances[" + std::to_string(i) + "]";
      r.onlyKeys(a, path, {"file", "fitSize", "onGround", "name", "placements"});
      LayoutAsset asset = readAsset(r, a, path, dir);
      auto it = a.find("placements");
      if (it == a.end() || !it->is_array())
        r.fail(Kind::Malformed, path + ".placements", "expected an array");
      for (std::size_t k = 0; k < it->size(); ++k) {
        const std::string p = path + ".placements[" + std::to_string(k) + "]";
        r.onlyKeys((*it)[k], p, {"translation", "rotation", "scale"});
        asset.placements.push_back(readPlacement(r, (*it)[k], p));
      }
      layout.assets.push_back(std::move(asset));
    }
  }
  if (const Json* boxes = r.array(root, "boxes")) {
    for (std::size_t i = 0; i < boxes->size(); ++i) {
      const Json& b = (*boxes)[i];
      const std::string path = "boxes[" + std::to_string(i) + "]";
      r.onlyKeys(b, path, {"min", "max", "albedo", "emission", "name"});
      if (!b.contains("min") || !b.contains("max"))
        r.fail(Kind::Malformed, path, "needs both min and max");
      const glm::dvec3 lo = r.numbers<3>(b, path, "min", glm::dvec3(0.0));
      const glm::dvec3 hi = r.numbers<3>(b, path, "max", glm::dvec3(0.0));
      if (!(lo.x < hi.x && lo.y < hi.y && lo.z < hi.z))
        r.fail(Kind::Malformed, path + ".max", "must be greater than min on every axis");
      Material m;
      m.name = path;
      if (auto n = b.find("name"); n != b.end()) {
        if (!n->is_string()) r.fail(Kind::Malformed, path + ".name", "expected a string");
        m.name = n->get<std::string>();
      }
      m.baseColorFactor = glm::vec4(glm::vec3(r.numbers<3>(b, path, "albedo", glm::dvec3(0.8))), 1);
      m.emissive = glm::vec3(r.numbers<3>(b, path, "emission", glm::dvec3(0.0)));
      appendTransformed(layout.boxes, makeBox(glm::vec3(lo), glm::vec3(hi), m), glm::dmat4(1.0));
    }
  }
  if (auto t = root.find("terrain"); t != root.end()) layout.terrain = readTerrain(r, *t, dir);
  if (auto c = root.find("comment"); c != root.end() && !c->is_string())
    r.fail(Kind::Malformed, "comment", "expected a string");
  return layout;
}

TriangleScene loadLayoutAsset(const ParsedLayout& layout, const LayoutAsset& asset) {
  try {
    std::string ext = asset.file.extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(), ::tolower);
    return ext == ".obj" ? loadObj(asset.file) : loadGltf(asset.file);
  } catch (const InputError& e) {
    throw InputError(e.kind(), layout.file, asset.key + ".file: " + e.what());
  }
}

glm::dmat4 placementTransform(const LayoutAsset& asset, const LayoutPlacement& placement,
                              const TriangleScene& scene) {
  // Asset frame first: fit, then rest on the ground; then T * R * S.
  glm::dmat4 local(1.0);
  const glm::dvec3 lo = scene.boundsMin(), hi = scene.boundsMax();
  double fit = 1.0;
  if (asset.fitSize) {
    const double extent = std::max({hi.x - lo.x, hi.y - lo.y, hi.z - lo.z});
    if (extent > 0.0) fit = *asset.fitSize / extent;
  }
  if (asset.onGround) local = glm::translate(local, glm::dvec3(0.0, -lo.y * fit, 0.0));
  local = glm::scale(local, glm::dvec3(fit));
  const glm::dmat4 world = glm::translate(glm::dmat4(1.0), placement.translation) *
                           glm::mat4_cast(placement.rotation) *
                           glm::scale(glm::dmat4(1.0), placement.scale);
  return world * local;
}

TriangleScene loadLayout(const std::filesystem::path& jsonFile) {
  const ParsedLayout layout = parseLayout(jsonFile);
  if (layout.terrain)
    throw InputError(Kind::Malformed, layout.file,
                     "terrain: a heightfield terrain needs the tiled world importer "
                     "(sdfstream import with a partition), not a single-grid scene");
  TriangleScene scene;
  scene.source = layout.file;
  for (const LayoutAsset& asset : layout.assets) {
    const TriangleScene part = loadLayoutAsset(layout, asset);
    for (const LayoutPlacement& p : asset.placements)
      appendTransformed(scene, part, placementTransform(asset, p, part));
  }
  appendTransformed(scene, layout.boxes, glm::dmat4(1.0));
  if (scene.triangles.empty()) throw InputError(Kind::Empty, layout.file, "no assets and no boxes");
  for (const glm::vec3& p : scene.positions)
    if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z))
      throw InputError(Kind::NonFinite, layout.file, "a transformed vertex is not finite");
  return scene;
}

}  // namespace sdfstream
