// Small glTF writers for tests: a file with one float VEC3 position buffer beside it.
#pragma once

#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <glm/glm.hpp>
#include <nlohmann/json.hpp>

#include "core/error.h"

namespace sdfstream::test {

inline void writeText(const std::filesystem::path& file, const std::string& text) {
  std::ofstream(file, std::ios::binary) << text;
}

// A glTF whose buffer 0 (file `<name>.bin`) holds `positions`; accessor 0 views all of them.
// The caller fills in nodes, meshes, materials, scenes.
inline nlohmann::json gltfWithPositions(const std::filesystem::path& dir, const std::string& name,
                                        const std::vector<glm::vec3>& positions) {
  std::vector<char> bytes(positions.size() * sizeof(glm::vec3));
  if (!bytes.empty()) std::memcpy(bytes.data(), positions.data(), bytes.size());
  std::ofstream(dir / (name + ".bin"), std::ios::binary)
      .write(bytes.data(), std::streamsize(bytes.size()));
  nlohmann::json j;
  j["asset"] = {{"version", "2.0"}};
  j["buffers"] = {{{"uri", name + ".bin"}, {"byteLength", bytes.size()}}};
  j["bufferViews"] = {{{"buffer", 0}, {"byteLength", bytes.size()}}};
  j["accessors"] = {
      {{"bufferView", 0}, {"componentType", 5126}, {"count", positions.size()}, {"type", "VEC3"}}};
  return j;
}

inline std::filesystem::path save(const std::filesystem::path& dir, const std::string& name,
                                  const nlohmann::json& j) {
  const auto file = dir / (name + ".gltf");
  writeText(file, j.dump(2));
  return file;
}

// Runs f, expects an InputError of `kind`; returns its message ("" when none was thrown).
template <class F>
std::string expectInputError(F&& f, InputErrorKind kind) {
  try {
    f();
  } catch (const InputError& e) {
    EXPECT_EQ(toString(e.kind()), std::string(toString(kind))) << e.what();
    const std::string msg = e.what();
    EXPECT_EQ(msg.find('\n'), std::string::npos) << "message must be one line: " << msg;
    return msg;
  }
  ADD_FAILURE() << "expected InputError " << toString(kind);
  return "";
}

}  // namespace sdfstream::test
