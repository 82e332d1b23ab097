// Internal to the glTF importer (world/gltf_*.cpp): the file's JSON, parsed with line:column
// errors and type-checked, and typed reads of the extension objects the type check does not
// descend into. Every read names its JSON path in the error, e.g. "bufferViews[3].extensions.
// EXT_meshopt_compression.count: expected a non-negative integer".
#pragma once

#include <cstddef>
#include <string>
#include <string_view>

#include <nlohmann/json.hpp>

namespace sdfstream::gltf {

using Json = nlohmann::json;

// Parses `text` and checks the types of every known glTF key wherever it appears (tinygltf
// silently ignores wrongly typed properties). Throws InputError Malformed naming the path.
Json parseAndCheckJson(std::string_view text, const std::string& file);

// Typed reads of an object's optional members; `where` is the object's JSON path for messages.
class JsonReader {
 public:
  JsonReader(const Json& object, std::string where, const std::string& file);

  bool has(const char* key) const;
  double number(const char* key, double fallback) const;
  std::size_t index(const char* key) const;  // required non-negative integer
  std::size_t index(const char* key, std::size_t fallback) const;
  std::string string(const char* key, const char* fallback) const;
  bool boolean(const char* key, bool fallback) const;
  // Exactly `n` numbers into out[0..n); out keeps its values (the defaults) when the key is
  // absent.
  void numbers(const char* key, double* out, std::size_t n) const;
  // The object extensions.<name>, or nullptr when absent (checkTypes saw it is an object).
  const Json* extension(const char* name) const;
  const std::string& where() const { return where_; }
  [[noreturn]] void fail(const char* key, const std::string& expected) const;

 private:
  const Json* member(const char* key) const;
  const Json& object_;
  std::string where_;
  const std::string& file_;
};

}  // namespace sdfstream::gltf
