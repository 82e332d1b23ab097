#include "world/gltf_materials.h"

#include <cmath>
#include <initializer_list>

#include <glm/gtc/type_ptr.hpp>

#include "core/error.h"
#include "world/gltf_accessor.h"

namespace sdfstream::gltf {
namespace {

using Kind = InputErrorKind;

// The member reached by `keys` from `j`, or nullptr when any step is absent.
const Json* find(const Json* j, std::initializer_list<const char*> keys) {
  for (const char* key : keys) {
    if (!j || !j->is_object()) return nullptr;
    auto it = j->find(key);
    j = it == j->end() ? nullptr : &*it;
  }
  return j;
}

// materials[i] of the file's JSON (tinygltf read the same array, so i is in range).
const Json* materialJson(const Json& root, std::size_t i) {
  const Json* list = find(&root, {"materials"});
  return list && list->is_array() && i < list->size() ? &(*list)[i] : nullptr;
}

}  // namespace

void MaterialImporter::fail(Kind kind, const std::string& problem) const {
  throw InputError(kind, file_, problem);
}

int MaterialImporter::importTexture(int texture, const std::string& where) {
  if (texture < 0) return -1;
  if (auto it = textureSlot_.find(texture); it != textureSlot_.end()) return it->second;
  if (std::size_t(texture) >= doc_.model.textures.size())
    fail(Kind::OutOfRange, where + ": texture " + std::to_string(texture) + " does not exist");
  const int source = doc_.model.textures[std::size_t(texture)].source;
  if (source < 0) return textureSlot_[texture] = -1;  // only extension sources (e.g. KTX2)
  if (std::size_t(source) >= doc_.model.images.size())
    fail(Kind::OutOfRange, label("texture", std::size_t(texture)) + ": image " +
                               std::to_string(source) + " does not exist");
  const tinygltf::Image& img = doc_.model.images[std::size_t(source)];
  const std::string imgName =
      label("image", std::size_t(source)) +
      (img.uri.empty() || img.uri.size() > 100 ? std::string() : " ('" + img.uri + "')");
  if (img.image.empty()) fail(Kind::MissingData, imgName + " could not be loaded");
  const int comp = img.component, bytesPer = img.bits == 16 ? 2 : 1;
  if (img.width <= 0 || img.height <= 0 || comp < 1 || comp > 4 ||
      (img.bits != 8 && img.bits != 16) ||
      img.image.size() != std::size_t(img.width) * std::size_t(img.height) * std::size_t(comp) *
                              std::size_t(bytesPer))
    fail(Kind::Malformed, imgName + ": unexpected decoded size or format");
  Texture tex;
  tex.width = img.width;
  tex.height = img.height;
  const std::size_t pixels = std::size_t(img.width) * std::size_t(img.height);
  tex.rgba.resize(pixels * 4);
  for (std::size_t p = 0; p < pixels; ++p) {
    // 16-bit: keep the high byte (little-endian as stb returns it in memory).
    auto channel = [&](int c) {
      return img.image[(p * std::size_t(comp) + std::size_t(c)) * std::size_t(bytesPer) +
                       std::size_t(bytesPer - 1)];
    };
    const bool grey = comp <= 2;
    tex.rgba[p * 4 + 0] = channel(0);
    tex.rgba[p * 4 + 1] = channel(grey ? 0 : 1);
    tex.rgba[p * 4 + 2] = channel(grey ? 0 : 2);
    tex.rgba[p * 4 + 3] = comp == 2 ? channel(1) : comp == 4 ? channel(3) : 255;
  }
  scene_.textures.push_back(std::move(tex));
  return textureSlot_[texture] = int(scene_.textures.size() - 1);
}


void MaterialImporter::readTransform(const Json* textureInfo, const std::string& where,
                                     UvTransform& uv, int& texCoord) const {
  if (!textureInfo) return;
  const JsonReader info(*textureInfo, where, file_);
  const Json* ext = info.extension("KHR_texture_transform");
  if (!ext) return;
  const JsonReader t(*ext, where + ".extensions.KHR_texture_transform", file_);
  double offset[2] = {0.0, 0.0}, scale[2] = {1.0, 1.0};
  t.numbers("offset", offset, 2);
  t.numbers("scale", scale, 2);
  const double rotation = t.number("rotation", 0.0);
  if (!std::isfinite(offset[0] + offset[1] + scale[0] + scale[1] + rotation))
    t.fail("offset", "offset, rotation and scale must be finite");
  // uv' = T * R * S * uv with R rotating the UVs counter-clockwise, the sense in which the
  // extension's own example (offset [0,1], rotation pi/2, scale 0.5) selects the image's lower
  // left quadrant: u' = sx u cos + sy v sin + ox, v' = -sx u sin + sy v cos + oy.
  const double c = std::cos(rotation), s = std::sin(rotation);
  uv.column0 = glm::vec2(float(scale[0] * c), float(-scale[0] * s));
  uv.column1 = glm::vec2(float(scale[1] * s), float(scale[1] * c));
  uv.offset = glm::vec2(float(offset[0]), float(offset[1]));
  if (t.has("texCoord")) texCoord = int(std::min<std::size_t>(t.index("texCoord"), 1u << 20));
}

void MaterialImporter::importAll() {
  const tinygltf::Model& model = doc_.model;
  for (std::size_t i = 0; i < model.materials.size(); ++i) {
    const tinygltf::Material& gm = model.materials[i];
    const std::string where = label("materials", i);
    const std::string path = "materials[" + std::to_string(i) + "]";  // JSON path of extensions
    Material m;
    m.name = gm.name;
    const auto& pbr = gm.pbrMetallicRoughness;
    if (pbr.baseColorFactor.size() == 4)
      m.baseColorFactor = glm::vec4(glm::make_vec4(pbr.baseColorFactor.data()));
    m.baseColorTexture = importTexture(pbr.baseColorTexture.index, where);
    m.baseColorTexCoord = pbr.baseColorTexture.texCoord;
    const Json* json = materialJson(doc_.json, i);
    readTransform(find(json, {"pbrMetallicRoughness", "baseColorTexture"}),
                  path + ".pbrMetallicRoughness.baseColorTexture", m.baseColorUv,
                  m.baseColorTexCoord);
    // The archived specular-glossiness model: its diffuse colour is the closest to a base colour
    // and is all a Lambertian GI reads (gltfpack writes both; older exporters only this one).
    const Json* sg = find(json, {"extensions", "KHR_materials_pbrSpecularGlossiness"});
    if (sg && !find(json, {"pbrMetallicRoughness"})) {
      const JsonReader r(*sg, path + ".extensions.KHR_materials_pbrSpecularGlossiness", file_);
      double diffuse[4] = {1.0, 1.0, 1.0, 1.0};
      r.numbers("diffuseFactor", diffuse, 4);
      m.baseColorFactor = glm::vec4(glm::make_vec4(diffuse));
      if (const auto it = sg->find("diffuseTexture"); it != sg->end()) {
        const JsonReader t(*it, r.where() + ".diffuseTexture", file_);
        m.baseColorTexture = importTexture(int(std::min<std::size_t>(t.index("index"), 1u << 30)), where);
        m.baseColorTexCoord = int(std::min<std::size_t>(t.index("texCoord", 0), 1u << 20));
        readTransform(&*it, t.where(), m.baseColorUv, m.baseColorTexCoord);
      }
    }
    double strength = 1.0;
    if (auto it = gm.extensions.find("KHR_materials_emissive_strength");
        it != gm.extensions.end() && it->second.Has("emissiveStrength"))
      strength = it->second.Get("emissiveStrength").GetNumberAsDouble();
    if (gm.emissiveFactor.size() == 3)
      m.emissive = glm::vec3(glm::make_vec3(gm.emissiveFactor.data()) * strength);
    m.emissiveTexture = importTexture(gm.emissiveTexture.index, where);
    m.emissiveTexCoord = gm.emissiveTexture.texCoord;
    readTransform(find(json, {"emissiveTexture"}), path + ".emissiveTexture",
                  m.emissiveUv, m.emissiveTexCoord);
    if (!std::isfinite(m.baseColorFactor.x + m.baseColorFactor.y + m.baseColorFactor.z +
                       m.baseColorFactor.w + m.emissive.x + m.emissive.y + m.emissive.z))
      fail(Kind::NonFinite, where + ": colour factor is not finite");
    scene_.materials.push_back(std::move(m));
  }
}

}  // namespace sdfstream::gltf
