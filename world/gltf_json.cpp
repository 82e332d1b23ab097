#include "world/gltf_json.h"

#include <algorithm>
#include <map>
#include <utility>

#include "core/error.h"
#include "world/gltf_import.h"

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

namespace gltf {
namespace {

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

}  // namespace

Json parseAndCheckJson(std::string_view text, const std::string& file) {
  Json json;
  try {
    json = Json::parse(text.begin(), text.end());
  } catch (const Json::parse_error& e) {
    // nlohmann's message: "[json.exception.parse_error.101] parse error at ...: <reason>".
    std::string reason = e.what();
    if (auto colon = reason.find(": "); colon != std::string::npos) reason.erase(0, colon + 2);
    throw InputError(Kind::Malformed, file,
                     "invalid JSON at " + detail::jsonLineColumn(text, e.byte) + ": " + reason);
  } catch (const Json::exception& e) {
    // Not only parse_error: a number too large for a double ("1e999") is out_of_range (406).
    std::string reason = e.what();
    if (auto bracket = reason.find("] "); bracket != std::string::npos) reason.erase(0, bracket + 2);
    throw InputError(Kind::Malformed, file, "invalid JSON: " + reason.substr(0, 200));
  }
  if (!json.is_object()) throw InputError(Kind::Malformed, file, "top level is not a JSON object");
  if (nestedDeeperThan(json, 64)) throw InputError(Kind::Malformed, file, "JSON nested too deeply");
  checkTypes(json, "", file);
  return json;
}

JsonReader::JsonReader(const Json& object, std::string where, const std::string& file)
    : object_(object), where_(std::move(where)), file_(file) {
  if (!object_.is_object()) throw InputError(Kind::Malformed, file_, where_ + ": expected an object");
}

const Json* JsonReader::member(const char* key) const {
  auto it = object_.find(key);
  return it == object_.end() ? nullptr : &*it;
}

void JsonReader::fail(const char* key, const std::string& expected) const {
  throw InputError(Kind::Malformed, file_, where_ + "." + key + ": " + expected);
}

bool JsonReader::has(const char* key) const { return member(key) != nullptr; }

double JsonReader::number(const char* key, double fallback) const {
  const Json* v = member(key);
  if (!v) return fallback;
  if (!v->is_number()) fail(key, "expected a number");
  return v->get<double>();
}

std::size_t JsonReader::index(const char* key) const {
  if (!member(key)) fail(key, "is required");
  return index(key, 0);
}

std::size_t JsonReader::index(const char* key, std::size_t fallback) const {
  const Json* v = member(key);
  if (!v) return fallback;
  if (!v->is_number_unsigned()) fail(key, "expected a non-negative integer");
  return v->get<std::size_t>();
}

std::string JsonReader::string(const char* key, const char* fallback) const {
  const Json* v = member(key);
  if (!v) return fallback;
  if (!v->is_string()) fail(key, "expected a string");
  return v->get<std::string>();
}

bool JsonReader::boolean(const char* key, bool fallback) const {
  const Json* v = member(key);
  if (!v) return fallback;
  if (!v->is_boolean()) fail(key, "expected true or false");
  return v->get<bool>();
}

void JsonReader::numbers(const char* key, double* out, std::size_t n) const {
  const Json* v = member(key);
  if (!v) return;
  if (!v->is_array() || v->size() != n ||
      !std::all_of(v->begin(), v->end(), [](const Json& e) { return e.is_number(); }))
    fail(key, "expected " + std::to_string(n) + " numbers");
  for (std::size_t i = 0; i < n; ++i) out[i] = (*v)[i].get<double>();
}

const Json* JsonReader::extension(const char* name) const {
  const Json* ext = member("extensions");
  if (!ext || !ext->is_object()) return nullptr;
  auto it = ext->find(name);
  return it == ext->end() ? nullptr : &*it;
}

}  // namespace gltf
}  // namespace sdfstream
