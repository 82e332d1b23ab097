// Internal to the glTF importer (world/gltf_*.cpp): a .gltf or .glb file read, checked and
// loaded by tinygltf, with the extensions that change how its bytes are read already applied
// (EXT_meshopt_compression decoded). The JSON stays beside the model: the importer reads the
// extensions it supports from it, independent of which extensions tinygltf's version knows.
#pragma once

#include <filesystem>
#include <string>

// Debian's libtinygltf.so carries the implementation (built with its default options: stb_image
// and nlohmann json); the header is only the interface here.
#include <tiny_gltf.h>

#include "world/gltf_json.h"

namespace sdfstream::gltf {

// The extensions a file may list in extensionsRequired; any other is refused (Unsupported) with
// its name, since rendering the file without it would be wrong in ways nobody would notice.
// KHR_materials_pbrSpecularGlossiness's diffuse colour and texture stand in for the base colour.
inline constexpr const char* kSupportedRequiredExtensions[] = {
    "KHR_mesh_quantization",        "EXT_meshopt_compression",
    "KHR_texture_transform",        "KHR_materials_emissive_strength",
    "KHR_lights_punctual",          "KHR_materials_pbrSpecularGlossiness",
};

struct Document {
  tinygltf::Model model;
  Json json;
};

// Reads, checks and loads `path` (`file` is the name errors give). Throws InputError.
Document loadDocument(const std::filesystem::path& path, const std::string& file);

}  // namespace sdfstream::gltf
