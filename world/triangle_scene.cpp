#include "world/triangle_scene.h"

#include <array>
#include <cassert>
#include <cmath>
#include <limits>
#include <optional>

namespace sdfstream {
namespace {

// sRGB 8-bit code → linear, per the sRGB EOTF (IEC 61966-2-1); a table because every texel tap
// decodes before filtering (filtering encoded values would darken edges).
const std::array<float, 256>& srgbToLinearTable() {
  static const std::array<float, 256> table = [] {
    std::array<float, 256> t{};
    for (int i = 0; i < 256; ++i) {
      const double c = i / 255.0;
      t[i] = float(c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4));
    }
    return t;
  }();
  return table;
}

int wrapRepeat(int i, int n) {
  const int m = i % n;
  return m < 0 ? m + n : m;
}

// Bilinear tap with REPEAT wrap; rgb decoded from sRGB, alpha linear. Texel centres at (i+0.5)/w.
glm::vec4 sampleTexture(const Texture& tex, glm::vec2 uv) {
  if (tex.width <= 0 || tex.height <= 0 ||
      tex.rgba.size() != std::size_t(tex.width) * std::size_t(tex.height) * 4)
    return glm::vec4(1.0f);
  if (!std::isfinite(uv.x) || !std::isfinite(uv.y)) uv = glm::vec2(0.0f);
  // Reduce to [0,1) first so large UVs keep float precision in the texel coordinate.
  uv -= glm::floor(uv);
  const float x = uv.x * float(tex.width) - 0.5f;
  const float y = uv.y * float(tex.height) - 0.5f;
  const float x0f = std::floor(x), y0f = std::floor(y);
  const float fx = x - x0f, fy = y - y0f;
  const int x0 = int(x0f), y0 = int(y0f);
  const auto& lut = srgbToLinearTable();
  auto texel = [&](int tx, int ty) {
    const std::size_t i = (std::size_t(wrapRepeat(ty, tex.height)) * std::size_t(tex.width) +
                           std::size_t(wrapRepeat(tx, tex.width))) *
                          4;
    return glm::vec4(lut[tex.rgba[i]], lut[tex.rgba[i + 1]], lut[tex.rgba[i + 2]],
                     tex.rgba[i + 3] / 255.0f);
  };
  const glm::vec4 top = glm::mix(texel(x0, y0), texel(x0 + 1, y0), fx);
  const glm::vec4 bottom = glm::mix(texel(x0, y0 + 1), texel(x0 + 1, y0 + 1), fx);
  return glm::mix(top, bottom, fy);
}

// The texture tap of one material slot, or nullopt when the slot has no texture or the scene
// lacks its UV set (the factor alone then applies, as before multiple sets were imported).
std::optional<glm::vec4> sampleSlot(const TriangleScene& scene, std::uint32_t triangle,
                                    glm::vec2 bary, int texture, int texCoord,
                                    const UvTransform& transform) {
  if (texture < 0 || std::size_t(texture) >= scene.textures.size()) return std::nullopt;
  if (texCoord != 0 && texCoord != 1) return std::nullopt;
  const std::vector<glm::vec2>& uvs = texCoord == 1 ? scene.uvs1 : scene.uvs;
  if (uvs.size() != scene.positions.size()) return std::nullopt;
  const glm::uvec3 t = scene.triangles[triangle];
  const glm::vec2 uv = uvs[t.x] * (1.0f - bary.x - bary.y) + uvs[t.y] * bary.x + uvs[t.z] * bary.y;
  return sampleTexture(scene.textures[std::size_t(texture)], transform.apply(uv));
}

const Material& materialOf(const TriangleScene& scene, std::uint32_t triangle) {
  assert(triangle < scene.triangles.size() && triangle < scene.triangleMaterial.size());
  const std::uint32_t m = scene.triangleMaterial[triangle];
  assert(m < scene.materials.size());
  return scene.materials[m];
}

}  // namespace

glm::vec3 TriangleScene::boundsMin() const {
  if (positions.empty()) return glm::vec3(0.0f);
  glm::vec3 lo(std::numeric_limits<float>::infinity());
  for (const glm::vec3& p : positions) lo = glm::min(lo, p);
  return lo;
}

glm::vec3 TriangleScene::boundsMax() const {
  if (positions.empty()) return glm::vec3(0.0f);
  glm::vec3 hi(-std::numeric_limits<float>::infinity());
  for (const glm::vec3& p : positions) hi = glm::max(hi, p);
  return hi;
}

double TriangleScene::surfaceArea() const {
  double area = 0.0;
  for (const glm::uvec3& t : triangles) {
    const glm::dvec3 a(positions[t.x]), b(positions[t.y]), c(positions[t.z]);
    area += 0.5 * glm::length(glm::cross(b - a, c - a));
  }
  return area;
}

glm::vec4 sampleAlbedo(const TriangleScene& scene, std::uint32_t triangle, glm::vec2 bary) {
  const Material& m = materialOf(scene, triangle);
  glm::vec4 color = m.baseColorFactor;
  if (auto tap = sampleSlot(scene, triangle, bary, m.baseColorTexture, m.baseColorTexCoord,
                            m.baseColorUv))
    color *= *tap;
  return color;
}

glm::vec3 sampleEmission(const TriangleScene& scene, std::uint32_t triangle, glm::vec2 bary) {
  const Material& m = materialOf(scene, triangle);
  glm::vec3 emission = m.emissive;
  if (emission == glm::vec3(0.0f)) return emission;
  if (auto tap = sampleSlot(scene, triangle, bary, m.emissiveTexture, m.emissiveTexCoord,
                            m.emissiveUv))
    emission *= glm::vec3(*tap);
  return emission;
}

}  // namespace sdfstream
