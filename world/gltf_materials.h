// Internal to the glTF importer: materials and their textures, with KHR_texture_transform,
// KHR_materials_emissive_strength and KHR_materials_pbrSpecularGlossiness's diffuse colour.
#pragma once

#include <map>
#include <string>

#include "core/error.h"
#include "world/gltf_document.h"
#include "world/triangle_scene.h"

namespace sdfstream::gltf {

// Appends the file's materials to scene.materials in glTF order (so primitives keep their
// indices) and the textures they use to scene.textures (RGBA8; other channel counts and 16-bit
// images converted). Throws InputError naming the material, texture or image.
class MaterialImporter {
 public:
  MaterialImporter(const Document& doc, const std::string& file, TriangleScene& scene)
      : doc_(doc), file_(file), scene_(scene) {}
  void importAll();

 private:
  // glTF texture index → scene.textures index (-1 when its image comes from an extension only).
  int importTexture(int texture, const std::string& where);
  // Reads a textureInfo's KHR_texture_transform into `uv` and its texCoord override.
  void readTransform(const Json* textureInfo, const std::string& where, UvTransform& uv,
                     int& texCoord) const;
  [[noreturn]] void fail(InputErrorKind kind, const std::string& problem) const;

  const Document& doc_;
  const std::string& file_;
  TriangleScene& scene_;
  std::map<int, int> textureSlot_;
};

}  // namespace sdfstream::gltf
