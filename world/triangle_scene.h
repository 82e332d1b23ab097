// Triangles in world space with their materials: what glTF (and layout) import produce, what the
// mesh-to-SDF step, Embree reference tests and the path tracer consume.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "world/scene_lights.h"

namespace sdfstream {

// A decoded texture, linear 8-bit RGBA rows top to bottom as stored in the image file.
struct Texture {
  int width = 0;
  int height = 0;
  std::vector<std::uint8_t> rgba;  // width*height*4, sRGB-encoded as in the file
};

// KHR_texture_transform as the affine map uv' = column0 * u + column1 * v + offset.
struct UvTransform {
  glm::vec2 column0{1.0f, 0.0f};
  glm::vec2 column1{0.0f, 1.0f};
  glm::vec2 offset{0.0f};

  glm::vec2 apply(glm::vec2 uv) const { return column0 * uv.x + column1 * uv.y + offset; }
  bool isIdentity() const {
    return column0 == glm::vec2(1, 0) && column1 == glm::vec2(0, 1) && offset == glm::vec2(0);
  }
};

struct Material {
  glm::vec4 baseColorFactor{1.0f};  // linear, glTF pbrMetallicRoughness.baseColorFactor
  int baseColorTexture = -1;        // index into TriangleScene::textures, or -1
  int baseColorTexCoord = 0;        // UV set 0 or 1; any other falls back to the factor alone
  UvTransform baseColorUv;          // applied to the UV before the base colour tap
  glm::vec3 emissive{0.0f};         // linear; emissiveFactor * KHR_materials_emissive_strength
  int emissiveTexture = -1;         // index into textures, or -1
  int emissiveTexCoord = 0;         // as baseColorTexCoord
  UvTransform emissiveUv;
  std::string name;
};

struct TriangleScene {
  std::vector<glm::vec3> positions;   // world space (all node transforms applied)
  std::vector<glm::vec2> uvs;         // TEXCOORD_0, one per position (zero where absent)
  std::vector<glm::vec2> uvs1;        // TEXCOORD_1: empty, or one per position (zero where absent)
  std::vector<glm::uvec3> triangles;  // indices into positions
  std::vector<std::uint32_t> triangleMaterial;  // one per triangle, index into materials
  std::vector<Material> materials;  // never empty after import (a default grey is added)
  std::vector<Texture> textures;
  std::vector<SceneLight> lights;  // the file's own lights (glTF KHR_lights_punctual), if any
  std::string source;              // file the scene came from

  glm::vec3 boundsMin() const;
  glm::vec3 boundsMax() const;
  double surfaceArea() const;
};

// Linear base colour (factor × texture, texture decoded from sRGB) at a point on a triangle
// given barycentric coordinates (b1, b2) of vertices 1 and 2.
glm::vec4 sampleAlbedo(const TriangleScene& scene, std::uint32_t triangle, glm::vec2 bary);
// Linear emission at the same point.
glm::vec3 sampleEmission(const TriangleScene& scene, std::uint32_t triangle, glm::vec2 bary);

// Box-filtered mip chains of a scene's textures (each level half the one above, averaged in
// linear light and re-encoded as sRGB), for taps that cover a footprint: what a rasterizer's
// trilinear sampler does, so a texture seen from afar shows its mean, not aliased texels.
// levels[t][k] is level k + 1 of scene.textures[t] (level 0 is the texture itself).
struct TexturePyramid {
  std::vector<std::vector<Texture>> levels;
};
TexturePyramid buildTexturePyramid(const TriangleScene& scene);
// sampleAlbedo / sampleEmission filtered over a footprint of `footprint` metres on the surface
// (a pixel's size there): the mip level follows the triangle's texels per metre, with a
// trilinear tap between the two nearest levels. footprint <= 0: the unfiltered tap.
glm::vec4 sampleAlbedo(const TriangleScene& scene, const TexturePyramid& pyramid,
                       std::uint32_t triangle, glm::vec2 bary, float footprint);
glm::vec3 sampleEmission(const TriangleScene& scene, const TexturePyramid& pyramid,
                         std::uint32_t triangle, glm::vec2 bary, float footprint);

}  // namespace sdfstream
