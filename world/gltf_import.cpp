#include "world/gltf_import.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <iterator>
#include <map>
#include <optional>
#include <utility>
#include <vector>

#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/quaternion.hpp>
#include <glm/gtc/type_ptr.hpp>
#include <nlohmann/json.hpp>
// Debian's libtinygltf.so carries the implementation (built with its default options: stb_image
// and nlohmann json); the header is only the interface here.
#include <tiny_gltf.h>

#include "core/error.h"

namespace sdfstream {

namespace detail {
std::string jsonLineColumn(std::string_view text, std::size_t byte) {
  const std::size_t pos = std::min(byte > 0 ? byte - 1 : 0, text.size());
  std::size_t line = 1, lineStart = 0;
  for (std::size_t i = 0; i < pos; ++i)
    if (text[i] == '\n') ++line, lineStart = i + 1;
  return "line " + std::to_string(line) + ", column " + std::to_string(pos - lineStart + 1);
}
}  // namespace detail

namespace {

using Json = nlohmann::json;
using Kind = InputErrorKind;

// ---------------------------------------------------------------------------------------------
// JSON type check. tinygltf silently ignores properties of the wrong type (a "primitives" object
// yields a mesh without primitives), so the known glTF keys are checked first, wherever they
// appear, with a path for the message ("meshes[0].primitives: expected an array").

enum class Rule {
  String,
  Uint,
  Number,
  Bool,
  Object,
  ObjectArray,
  UintArray,
  NumberArray,
  StringArray,
  Attributes,    // object whose values are accessor indices
  UintOrObject,  // "indices" (primitive: accessor; sparse: object), "target" (bufferView/channel)
  Scale,         // node: 3 numbers; normalTexture: a number
  NodesKey,      // root: array of node objects; scene: array of node indices
  Extensions,    // object of objects; contents not descended (extensions reuse names loosely)
  Extras,        // anything
};

struct KeyRule {
  Rule rule;
  int length = -1;  // NumberArray length, -1 for any
};

const std::map<std::string, KeyRule, std::less<>>& keyRules() {
  static const std::map<std::string, KeyRule, std::less<>> rules = [] {
    std::map<std::string, KeyRule, std::less<>> r;
    for (const char* k : {"name", "uri", "mimeType", "type", "generator", "version", "minVersion",
                          "copyright", "alphaMode", "interpolation", "path"})
      r[k] = {Rule::String};
    for (const char* k :
         {"scene",      "index",      "texCoord",   "bufferView",    "buffer",
          "byteOffset", "byteLength", "byteStride", "componentType", "count",
          "mode",       "material",   "mesh",       "skin",          "camera",
          "source",     "sampler",    "input",      "output",        "node",
          "magFilter",  "minFilter",  "wrapS",      "wrapT",         "inverseBindMatrices"})
      r[k] = {Rule::Uint};
    for (const char* k : {"strength", "metallicFactor", "roughnessFactor", "alphaCutoff"})
      r[k] = {Rule::Number};
    for (const char* k : {"normalized", "doubleSided"}) r[k] = {Rule::Bool};
    for (const char* k : {"asset", "pbrMetallicRoughness", "baseColorTexture", "emissiveTexture",
                          "normalTexture", "occlusionTexture", "metallicRoughnessTexture", "sparse",
                          "values", "perspective", "orthographic"})
      r[k] = {Rule::Object};
    for (const char* k : {"scenes", "meshes", "primitives", "materials", "accessors", "bufferViews",
                          "buffers", "images", "textures", "samplers", "skins", "animations",
                          "cameras", "channels", "targets"})
      r[k] = {Rule::ObjectArray};
    for (const char* k : {"children", "joints"}) r[k] = {Rule::UintArray};
    for (const char* k : {"extensionsUsed", "extensionsRequired"}) r[k] = {Rule::StringArray};
    r["matrix"] = {Rule::NumberArray, 16};
    r["translation"] = {Rule::NumberArray, 3};
    r["rotation"] = {Rule::NumberArray, 4};
    r["baseColorFactor"] = {Rule::NumberArray, 4};
    r["emissiveFactor"] = {Rule::NumberArray, 3};
    for (const char* k : {"weights", "min", "max"}) r[k] = {Rule::NumberArray};
    r["attributes"] = {Rule::Attributes};
    r["indices"] = {Rule::UintOrObject};
    r["target"] = {Rule::UintOrObject};
    r["scale"] = {Rule::Scale};
    r["nodes"] = {Rule::NodesKey};
    r["extensions"] = {Rule::Extensions};
    r["extras"] = {Rule::Extras};
    return r;
  }();
  return rules;
}

bool allOf(const Json& a, bool (Json::*pred)() const) {
  return a.is_array() &&
         std::all_of(a.begin(), a.end(), [&](const Json& e) { return (e.*pred)(); });
}

// Returns what was expected when `v` breaks the rule, or nullptr.
const char* checkRule(const KeyRule& r, const Json& v, bool atRoot) {
  switch (r.rule) {
    case Rule::String:
      return v.is_string() ? nullptr : "expected a string";
    case Rule::Uint:
      return v.is_number_unsigned() ? nullptr : "expected a non-negative integer";
    case Rule::Number:
      return v.is_number() ? nullptr : "expected a number";
    case Rule::Bool:
      return v.is_boolean() ? nullptr : "expected true or false";
    case Rule::Object:
      return v.is_object() ? nullptr : "expected an object";
    case Rule::ObjectArray:
      return allOf(v, &Json::is_object) ? nullptr : "expected an array of objects";
    case Rule::UintArray:
      return allOf(v, &Json::is_number_unsigned) ? nullptr
                                                 : "expected an array of non-negative integers";
    case Rule::StringArray:
      return allOf(v, &Json::is_string) ? nullptr : "expected strings";
    case Rule::NumberArray:
      if (!allOf(v, &Json::is_number)) return "expected an array of numbers";
      if (r.length == 3 && v.size() != 3) return "expected 3 numbers";
      if (r.length == 4 && v.size() != 4) return "expected 4 numbers";
      if (r.length == 16 && v.size() != 16) return "expected 16 numbers";
      return nullptr;
    case Rule::Attributes:
      if (!v.is_object()) return "expected an object";
      for (const auto& [k, a] : v.items())
        if (!a.is_number_unsigned()) return "expected accessor indices";
      return nullptr;
    case Rule::UintOrObject:
      return v.is_number_unsigned() || v.is_object() ? nullptr : "expected an index or an object";
    case Rule::Scale:
      return v.is_number() || (allOf(v, &Json::is_number) && v.size() == 3)
                 ? nullptr
                 : "expected a number or 3 numbers";
    case Rule::NodesKey:
      if (atRoot) return allOf(v, &Json::is_object) ? nullptr : "expected an array of objects";
      return allOf(v, &Json::is_number_unsigned) ? nullptr
                                                 : "expected an array of non-negative integers";
    case Rule::Extensions:
      if (!v.is_object()) return "expected an object";
      for (const auto& [k, e] : v.items())
        if (!e.is_object()) return "expected an object for each extension";
      if (auto it = v.find("KHR_materials_emissive_strength"); it != v.end()) {
        auto s = it->find("emissiveStrength");
        if (s != it->end() && !(s->is_number() && s->get<double>() >= 0.0))
          return "KHR_materials_emissive_strength.emissiveStrength: expected a number >= 0";
      }
      return nullptr;
    case Rule::Extras:
      return nullptr;
  }
  return nullptr;
}

// Hostile files may nest arrays a million deep; this walk, and tinygltf's for extras, recurse.
bool nestedDeeperThan(const Json& j, int levels) {
  if (!j.is_structured()) return false;
  if (levels == 0) return true;
  for (const Json& e : j)
    if (nestedDeeperThan(e, levels - 1)) return true;
  return false;
}

void checkTypes(const Json& j, const std::string& path, const std::string& file) {
  const bool atRoot = path.empty();
  if (j.is_object()) {
    for (const auto& [key, value] : j.items()) {
      const std::string sub = atRoot ? key : path + "." + key;
      auto it = keyRules().find(key);
      if (it != keyRules().end()) {
        if (const char* expected = checkRule(it->second, value, atRoot))
          throw InputError(Kind::Malformed, file, sub + ": " + expected);
        if (it->second.rule == Rule::Extensions || it->second.rule == Rule::Extras) continue;
      }
      checkTypes(value, sub, file);
    }
  } else if (j.is_array()) {
    for (std::size_t i = 0; i < j.size(); ++i)
      checkTypes(j[i], path + "[" + std::to_string(i) + "]", file);
  }
}

// ---------------------------------------------------------------------------------------------
// File level: read, split .glb, check JSON, hand to tinygltf.

std::vector<unsigned char> readFile(const std::filesystem::path& path, const std::string& file) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec))
    throw InputError(Kind::Io, file, "is a directory, expected a .gltf or .glb file");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(Kind::Io, file, std::string("cannot open: ") + std::strerror(errno));
  std::vector<unsigned char> bytes((std::istreambuf_iterator<char>(in)),
                                   std::istreambuf_iterator<char>());
  if (in.bad()) throw InputError(Kind::Io, file, "read error");
  return bytes;
}

std::uint32_t readU32(const unsigned char* p) {
  return std::uint32_t(p[0]) | std::uint32_t(p[1]) << 8 | std::uint32_t(p[2]) << 16 |
         std::uint32_t(p[3]) << 24;
}

// Checks the GLB container (header, JSON chunk) and returns the JSON text and the container size.
std::pair<std::string_view, std::size_t> splitGlb(const std::vector<unsigned char>& bytes,
                                                  const std::string& file) {
  const std::size_t size = bytes.size();
  if (size > 0 && std::memcmp(bytes.data(), "glTF", std::min<std::size_t>(size, 4)) != 0)
    throw InputError(Kind::Malformed, file, "not a binary glTF file (bad magic)");
  if (size < 12)
    throw InputError(Kind::Truncated, file,
                     std::to_string(size) + " bytes, shorter than the 12-byte GLB header");
  if (readU32(&bytes[4]) != 2)
    throw InputError(Kind::Version, file,
                     "GLB version " + std::to_string(readU32(&bytes[4])) + ", expected 2");
  const std::size_t length = readU32(&bytes[8]);
  if (length > size)
    throw InputError(Kind::Truncated, file,
                     "GLB header declares " + std::to_string(length) + " bytes but the file has " +
                         std::to_string(size));
  if (length < 20) throw InputError(Kind::Truncated, file, "GLB ends before its JSON chunk");
  const std::size_t jsonLength = readU32(&bytes[12]);
  if (readU32(&bytes[16]) != 0x4E4F534Au)  // "JSON"
    throw InputError(Kind::Malformed, file, "first GLB chunk is not JSON");
  if (jsonLength > length - 20)
    throw InputError(Kind::Truncated, file, "GLB JSON chunk runs past the end of the file");
  return {std::string_view(reinterpret_cast<const char*>(&bytes[20]), jsonLength), length};
}

void parseAndCheckJson(std::string_view text, const std::string& file) {
  Json json;
  try {
    json = Json::parse(text.begin(), text.end());
  } catch (const Json::parse_error& e) {
    // nlohmann's message: "[json.exception.parse_error.101] parse error at ...: <reason>".
    std::string reason = e.what();
    if (auto colon = reason.find(": "); colon != std::string::npos) reason.erase(0, colon + 2);
    throw InputError(Kind::Malformed, file,
                     "invalid JSON at " + detail::jsonLineColumn(text, e.byte) + ": " + reason);
  }
  if (!json.is_object()) throw InputError(Kind::Malformed, file, "top level is not a JSON object");
  if (nestedDeeperThan(json, 64)) throw InputError(Kind::Malformed, file, "JSON nested too deeply");
  checkTypes(json, "", file);
}

// tinygltf's messages can span lines and embed whole data URIs: keep the first line, bounded.
[[noreturn]] void throwTinygltfError(const std::string& err, const std::string& file) {
  std::string line = err.substr(0, err.find('\n'));
  if (line.empty()) line = "tinygltf could not load the file";
  if (line.size() > 200) line = line.substr(0, 200) + "...";
  Kind kind = Kind::Malformed;
  if (line.find("File not found") != std::string::npos ||
      line.find("File open error") != std::string::npos)
    kind = Kind::MissingData;
  else if (line.find("size mismatch") != std::string::npos ||
           line.find("Invalid `byteLength'") != std::string::npos ||
           line.find("empty BIN chunk") != std::string::npos ||
           line.find("Invalid glTF binary") != std::string::npos)
    kind = Kind::Truncated;
  throw InputError(kind, file, line);
}

tinygltf::Model loadModel(const std::filesystem::path& path, const std::string& file) {
  const std::vector<unsigned char> bytes = readFile(path, file);
  const bool binary = path.extension() == ".glb" ||
                      (bytes.size() >= 4 && std::memcmp(bytes.data(), "glTF", 4) == 0);
  tinygltf::TinyGLTF loader;
  tinygltf::Model model;
  std::string err, warn;
  const std::string baseDir = path.parent_path().string();
  bool ok = false;
  if (binary) {
    const auto [json, length] = splitGlb(bytes, file);
    parseAndCheckJson(json, file);
    ok = loader.LoadBinaryFromMemory(&model, &err, &warn, bytes.data(), unsigned(length), baseDir);
  } else {
    const std::string_view text(reinterpret_cast<const char*>(bytes.data()), bytes.size());
    parseAndCheckJson(text, file);
    ok = loader.LoadASCIIFromString(&model, &err, &warn, text.data(), unsigned(text.size()),
                                    baseDir);
  }
  if (!ok || !err.empty()) throwTinygltfError(err, file);
  return model;
}

// ---------------------------------------------------------------------------------------------
// Accessors: a bounds-checked strided view of one accessor.

struct AccessorView {
  const unsigned char* data = nullptr;
  std::size_t stride = 0;
  std::size_t count = 0;
  int componentType = 0;
  int components = 0;
  bool normalized = false;

  // Component c of element i as a double; normalized integers mapped to [0,1] / [-1,1].
  double get(std::size_t i, int c) const {
    const unsigned char* p = data + i * stride;
    auto load = [&](auto tag) {
      decltype(tag) v;
      std::memcpy(&v, p + std::size_t(c) * sizeof(v), sizeof(v));
      return v;
    };
    switch (componentType) {
      case TINYGLTF_COMPONENT_TYPE_FLOAT:
        return load(float{});
      case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: {
        const double v = load(std::uint8_t{});
        return normalized ? v / 255.0 : v;
      }
      case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: {
        const double v = load(std::uint16_t{});
        return normalized ? v / 65535.0 : v;
      }
      case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT:
        return load(std::uint32_t{});
      case TINYGLTF_COMPONENT_TYPE_BYTE: {
        const double v = load(std::int8_t{});
        return normalized ? std::max(v / 127.0, -1.0) : v;
      }
      case TINYGLTF_COMPONENT_TYPE_SHORT: {
        const double v = load(std::int16_t{});
        return normalized ? std::max(v / 32767.0, -1.0) : v;
      }
    }
    return 0.0;
  }
  std::uint32_t index(std::size_t i) const {
    const unsigned char* p = data + i * stride;
    switch (componentType) {
      case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE:
        return p[0];
      case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: {
        std::uint16_t v;
        std::memcpy(&v, p, 2);
        return v;
      }
      default: {
        std::uint32_t v;
        std::memcpy(&v, p, 4);
        return v;
      }
    }
  }
};

std::string label(const char* what, std::size_t i) {
  return std::string(what) + " " + std::to_string(i);
}

AccessorView viewAccessor(const tinygltf::Model& model, int index, const std::string& file) {
  if (index < 0 || std::size_t(index) >= model.accessors.size())
    throw InputError(Kind::OutOfRange, file,
                     label("accessor", std::size_t(index)) + " does not exist (the file has " +
                         std::to_string(model.accessors.size()) + ")");
  const tinygltf::Accessor& acc = model.accessors[std::size_t(index)];
  const std::string name = label("accessor", std::size_t(index));
  if (acc.sparse.isSparse)
    throw InputError(Kind::Malformed, file, name + ": sparse accessors are not supported");
  if (acc.bufferView < 0) throw InputError(Kind::MissingData, file, name + " has no bufferView");
  if (std::size_t(acc.bufferView) >= model.bufferViews.size())
    throw InputError(Kind::OutOfRange, file,
                     name + ": bufferView " + std::to_string(acc.bufferView) + " does not exist");
  const tinygltf::BufferView& bv = model.bufferViews[std::size_t(acc.bufferView)];
  const std::string bvName = label("bufferView", std::size_t(acc.bufferView));
  if (bv.buffer < 0 || std::size_t(bv.buffer) >= model.buffers.size())
    throw InputError(Kind::OutOfRange, file,
                     bvName + ": buffer " + std::to_string(bv.buffer) + " does not exist");
  const tinygltf::Buffer& buf = model.buffers[std::size_t(bv.buffer)];
  if (bv.byteOffset > buf.data.size() || bv.byteLength > buf.data.size() - bv.byteOffset)
    throw InputError(Kind::Truncated, file,
                     bvName + " needs bytes up to " +
                         std::to_string(bv.byteOffset + bv.byteLength) + " of buffer " +
                         std::to_string(bv.buffer) + ", which has only " +
                         std::to_string(buf.data.size()));
  const int componentSize = tinygltf::GetComponentSizeInBytes(std::uint32_t(acc.componentType));
  const int components = tinygltf::GetNumComponentsInType(std::uint32_t(acc.type));
  if (componentSize <= 0 || components <= 0)
    throw InputError(Kind::Malformed, file, name + ": unknown componentType or type");
  const std::size_t elementSize = std::size_t(componentSize) * std::size_t(components);
  const std::size_t stride = bv.byteStride ? bv.byteStride : elementSize;
  if (stride < elementSize)
    throw InputError(Kind::Malformed, file, bvName + ": byteStride is smaller than an element");
  AccessorView view;
  view.stride = stride;
  view.count = acc.count;
  view.componentType = acc.componentType;
  view.components = components;
  view.normalized = acc.normalized;
  if (acc.count == 0) return view;
  // count <= byteLength first, so the products below cannot overflow.
  if (acc.count > bv.byteLength || acc.byteOffset > bv.byteLength ||
      (acc.count - 1) * stride + elementSize > bv.byteLength - acc.byteOffset)
    throw InputError(Kind::OutOfRange, file,
                     name + " (" + std::to_string(acc.count) + " elements from byte " +
                         std::to_string(acc.byteOffset) + ") reads past the end of " + bvName);
  view.data = buf.data.data() + bv.byteOffset + acc.byteOffset;
  return view;
}

// ---------------------------------------------------------------------------------------------
// Scene assembly.

glm::dmat4 localTransform(const tinygltf::Node& node) {
  if (node.matrix.size() == 16) return glm::make_mat4(node.matrix.data());  // column-major
  glm::dmat4 m(1.0);
  if (node.translation.size() == 3) m = glm::translate(m, glm::make_vec3(node.translation.data()));
  if (node.rotation.size() == 4) {
    const auto& q = node.rotation;
    m *= glm::mat4_cast(glm::normalize(glm::dquat(q[3], q[0], q[1], q[2])));
  }
  if (node.scale.size() == 3) m = glm::scale(m, glm::make_vec3(node.scale.data()));
  return m;
}

struct Importer {
  const tinygltf::Model& model;
  const std::string& file;
  TriangleScene scene;
  std::map<int, int> textureSlot;  // glTF texture index → scene.textures index
  int defaultMaterial = -1;

  [[noreturn]] void fail(Kind kind, const std::string& problem) const {
    throw InputError(kind, file, problem);
  }

  int importTexture(int texture, const std::string& where) {
    if (texture < 0) return -1;
    if (auto it = textureSlot.find(texture); it != textureSlot.end()) return it->second;
    if (std::size_t(texture) >= model.textures.size())
      fail(Kind::OutOfRange, where + ": texture " + std::to_string(texture) + " does not exist");
    const int source = model.textures[std::size_t(texture)].source;
    if (source < 0) return textureSlot[texture] = -1;  // only extension sources (e.g. KTX2)
    if (std::size_t(source) >= model.images.size())
      fail(Kind::OutOfRange, label("texture", std::size_t(texture)) + ": image " +
                                 std::to_string(source) + " does not exist");
    const tinygltf::Image& img = model.images[std::size_t(source)];
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
    scene.textures.push_back(std::move(tex));
    return textureSlot[texture] = int(scene.textures.size() - 1);
  }

  void importMaterials() {
    for (std::size_t i = 0; i < model.materials.size(); ++i) {
      const tinygltf::Material& gm = model.materials[i];
      const std::string where = label("materials", i);
      Material m;
      m.name = gm.name;
      const auto& pbr = gm.pbrMetallicRoughness;
      if (pbr.baseColorFactor.size() == 4)
        m.baseColorFactor = glm::vec4(glm::make_vec4(pbr.baseColorFactor.data()));
      m.baseColorTexture = importTexture(pbr.baseColorTexture.index, where);
      m.baseColorTexCoord = pbr.baseColorTexture.texCoord;
      double strength = 1.0;
      if (auto it = gm.extensions.find("KHR_materials_emissive_strength");
          it != gm.extensions.end() && it->second.Has("emissiveStrength"))
        strength = it->second.Get("emissiveStrength").GetNumberAsDouble();
      if (gm.emissiveFactor.size() == 3)
        m.emissive = glm::vec3(glm::make_vec3(gm.emissiveFactor.data()) * strength);
      m.emissiveTexture = importTexture(gm.emissiveTexture.index, where);
      if (!std::isfinite(m.baseColorFactor.x + m.baseColorFactor.y + m.baseColorFactor.z +
                         m.baseColorFactor.w + m.emissive.x + m.emissive.y + m.emissive.z))
        fail(Kind::NonFinite, where + ": colour factor is not finite");
      scene.materials.push_back(std::move(m));
    }
  }

  std::uint32_t materialFor(int index, const std::string& where) {
    if (index >= 0) {
      if (std::size_t(index) >= model.materials.size())
        fail(Kind::OutOfRange, where + ": material " + std::to_string(index) + " does not exist");
      return std::uint32_t(index);
    }
    if (defaultMaterial < 0) {
      Material grey;
      grey.baseColorFactor = glm::vec4(0.8f, 0.8f, 0.8f, 1.0f);
      grey.name = "default";
      scene.materials.push_back(grey);
      defaultMaterial = int(scene.materials.size() - 1);
    }
    return std::uint32_t(defaultMaterial);
  }

  void importPrimitive(const tinygltf::Primitive& prim, const glm::dmat4& world,
                       const std::string& where) {
    if (prim.mode >= 0 && prim.mode <= 3) return;  // points and lines
    if (prim.mode != TINYGLTF_MODE_TRIANGLES && prim.mode != TINYGLTF_MODE_TRIANGLE_STRIP &&
        prim.mode != TINYGLTF_MODE_TRIANGLE_FAN)
      fail(Kind::Malformed, where + ": unknown mode " + std::to_string(prim.mode));
    auto pos = prim.attributes.find("POSITION");
    if (pos == prim.attributes.end()) fail(Kind::MissingData, where + " has no POSITION");
    const AccessorView positions = viewAccessor(model, pos->second, file);
    if (positions.componentType != TINYGLTF_COMPONENT_TYPE_FLOAT || positions.components != 3)
      fail(Kind::Malformed, where + ": POSITION must be float VEC3");

    const std::size_t base = scene.positions.size();
    const std::size_t vertexCount = positions.count;
    if (base + vertexCount > std::size_t(UINT32_MAX))
      fail(Kind::OutOfRange, where + ": more than 2^32 vertices in the scene");
    for (std::size_t i = 0; i < vertexCount; ++i) {
      const glm::dvec3 p(positions.get(i, 0), positions.get(i, 1), positions.get(i, 2));
      if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z))
        fail(Kind::NonFinite, where + ": POSITION accessor " + std::to_string(pos->second) +
                                  ", vertex " + std::to_string(i) + " is not finite");
      const glm::vec3 w(world * glm::dvec4(p, 1.0));
      if (!std::isfinite(w.x) || !std::isfinite(w.y) || !std::isfinite(w.z))
        fail(Kind::NonFinite,
             where + ": vertex " + std::to_string(i) + " is not finite after its node transform");
      scene.positions.push_back(w);
    }

    scene.uvs.resize(scene.positions.size(), glm::vec2(0.0f));
    if (auto uv = prim.attributes.find("TEXCOORD_0"); uv != prim.attributes.end()) {
      const AccessorView uvs = viewAccessor(model, uv->second, file);
      const bool floatOk = uvs.componentType == TINYGLTF_COMPONENT_TYPE_FLOAT;
      const bool normOk =
          uvs.normalized && (uvs.componentType == TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE ||
                             uvs.componentType == TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT);
      if (uvs.components != 2 || !(floatOk || normOk))
        fail(Kind::Malformed, where + ": TEXCOORD_0 must be VEC2 float or normalized u8/u16");
      if (uvs.count != vertexCount)
        fail(Kind::Malformed, where + ": TEXCOORD_0 and POSITION counts differ");
      for (std::size_t i = 0; i < vertexCount; ++i) {
        glm::vec2 t(float(uvs.get(i, 0)), float(uvs.get(i, 1)));
        if (!std::isfinite(t.x) || !std::isfinite(t.y)) t = glm::vec2(0.0f);
        scene.uvs[base + i] = t;
      }
    }

    std::vector<std::uint32_t> idx;
    if (prim.indices >= 0) {
      const AccessorView indices = viewAccessor(model, prim.indices, file);
      if (indices.components != 1 ||
          (indices.componentType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE &&
           indices.componentType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT &&
           indices.componentType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT))
        fail(Kind::Malformed, where + ": indices must be unsigned integer scalars");
      idx.resize(indices.count);
      for (std::size_t i = 0; i < indices.count; ++i) {
        idx[i] = indices.index(i);
        if (idx[i] >= vertexCount)
          fail(Kind::OutOfRange,
               where + ": index " + std::to_string(idx[i]) + " at position " + std::to_string(i) +
                   " of accessor " + std::to_string(prim.indices) +
                   " is not below the vertex count " + std::to_string(vertexCount));
      }
    } else {
      idx.resize(vertexCount);
      for (std::size_t i = 0; i < vertexCount; ++i) idx[i] = std::uint32_t(i);
    }

    const std::uint32_t material = materialFor(prim.material, where);
    const bool flip = glm::determinant(world) < 0.0;  // mirrored: keep CCW winding
    auto emit = [&](std::uint32_t a, std::uint32_t b, std::uint32_t c) {
      const std::uint32_t o = std::uint32_t(base);
      scene.triangles.push_back(flip ? glm::uvec3(a + o, c + o, b + o)
                                     : glm::uvec3(a + o, b + o, c + o));
      scene.triangleMaterial.push_back(material);
    };
    if (prim.mode == TINYGLTF_MODE_TRIANGLES) {
      for (std::size_t i = 0; i + 2 < idx.size(); i += 3) emit(idx[i], idx[i + 1], idx[i + 2]);
    } else if (prim.mode == TINYGLTF_MODE_TRIANGLE_STRIP) {
      for (std::size_t i = 0; i + 2 < idx.size(); ++i)  // glTF spec: odd triangles swap
        emit(idx[i], idx[i + 1 + i % 2], idx[i + 2 - i % 2]);
    } else {
      for (std::size_t i = 1; i + 1 < idx.size(); ++i) emit(idx[i], idx[i + 1], idx[0]);
    }
  }

  void importMesh(int meshIndex, const glm::dmat4& world, std::size_t node) {
    if (std::size_t(meshIndex) >= model.meshes.size())
      fail(Kind::OutOfRange,
           label("node", node) + ": mesh " + std::to_string(meshIndex) + " does not exist");
    const tinygltf::Mesh& mesh = model.meshes[std::size_t(meshIndex)];
    for (std::size_t p = 0; p < mesh.primitives.size(); ++p)
      importPrimitive(
          mesh.primitives[p], world,
          "meshes[" + std::to_string(meshIndex) + "].primitives[" + std::to_string(p) + "]");
  }

  std::vector<int> rootNodes() const {
    if (model.defaultScene >= 0 || !model.scenes.empty()) {
      const int s = std::max(model.defaultScene, 0);
      if (std::size_t(s) >= model.scenes.size())
        fail(Kind::OutOfRange, "scene " + std::to_string(s) + " does not exist");
      return model.scenes[std::size_t(s)].nodes;
    }
    std::vector<char> isChild(model.nodes.size(), 0);
    for (const tinygltf::Node& n : model.nodes)
      for (int c : n.children)
        if (c >= 0 && std::size_t(c) < isChild.size()) isChild[std::size_t(c)] = 1;
    std::vector<int> roots;
    for (std::size_t i = 0; i < model.nodes.size(); ++i)
      if (!isChild[i]) roots.push_back(int(i));
    return roots;
  }

  // Depth-first with an explicit stack: file-controlled depth must not overflow ours. glTF node
  // hierarchies are disjoint trees, so reaching a node twice means a cycle (or a shared child).
  void importNodes() {
    std::vector<char> visited(model.nodes.size(), 0);
    std::vector<std::pair<int, glm::dmat4>> stack;
    const std::vector<int> roots = rootNodes();
    for (auto it = roots.rbegin(); it != roots.rend(); ++it)
      stack.emplace_back(*it, glm::dmat4(1.0));
    while (!stack.empty()) {
      const auto [n, parent] = stack.back();
      stack.pop_back();
      if (n < 0 || std::size_t(n) >= model.nodes.size())
        fail(Kind::OutOfRange, label("node", std::size_t(n)) + " does not exist");
      if (visited[std::size_t(n)])
        fail(Kind::Malformed,
             label("node", std::size_t(n)) + " is reached twice: the node hierarchy has a cycle");
      visited[std::size_t(n)] = 1;
      const tinygltf::Node& node = model.nodes[std::size_t(n)];
      const glm::dmat4 world = parent * localTransform(node);
      if (node.mesh >= 0) importMesh(node.mesh, world, std::size_t(n));
      for (auto c = node.children.rbegin(); c != node.children.rend(); ++c)
        stack.emplace_back(*c, world);
    }
  }
};

}  // namespace

TriangleScene loadGltf(const std::filesystem::path& path) {
  const std::string file = path.string();
  const tinygltf::Model model = loadModel(path, file);
  Importer importer{model, file, {}, {}, -1};
  importer.scene.source = file;
  importer.importMaterials();
  importer.importNodes();
  if (importer.scene.triangles.empty())
    throw InputError(Kind::Empty, file, "the scene has no triangles");
  if (importer.scene.materials.empty()) importer.materialFor(-1, "");
  return std::move(importer.scene);
}

}  // namespace sdfstream
