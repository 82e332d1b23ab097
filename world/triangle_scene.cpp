#include "world/triangle_scene.h"

#include <algorithm>
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
// With a pyramid and a footprint > 0 (metres on the surface), the tap is trilinear over the
// mip levels whose texels match the footprint.
std::optional<glm::vec4> sampleSlot(const TriangleScene& scene, std::uint32_t triangle,
                                    glm::vec2 bary, int texture, int texCoord,
                                    const UvTransform& transform,
                                    const TexturePyramid* pyramid = nullptr,
                                    float footprint = 0.0f) {
  if (texture < 0 || std::size_t(texture) >= scene.textures.size()) return std::nullopt;
  if (texCoord != 0 && texCoord != 1) return std::nullopt;
  const std::vector<glm::vec2>& uvs = texCoord == 1 ? scene.uvs1 : scene.uvs;
  if (uvs.size() != scene.positions.size()) return std::nullopt;
  const glm::uvec3 t = scene.triangles[triangle];
  const glm::vec2 uv = uvs[t.x] * (1.0f - bary.x - bary.y) + uvs[t.y] * bary.x + uvs[t.z] * bary.y;
  const Texture& base = scene.textures[std::size_t(texture)];
  const glm::vec2 at = transform.apply(uv);
  if (!pyramid || !(footprint > 0.0f) || std::size_t(texture) >= pyramid->levels.size() ||
      pyramid->levels[std::size_t(texture)].empty())
    return sampleTexture(base, at);
  // Texels per metre on this triangle: sqrt of the texel area over the surface area, the UV
  // transform's area scale included.
  const glm::vec3 p0 = scene.positions[t.x], p1 = scene.positions[t.y], p2 = scene.positions[t.z];
  const float worldArea = glm::length(glm::cross(p1 - p0, p2 - p0));
  const glm::vec2 e1 = uvs[t.y] - uvs[t.x], e2 = uvs[t.z] - uvs[t.x];
  const float uvScale = std::abs(transform.column0.x * transform.column1.y -
                                 transform.column0.y * transform.column1.x);
  const float uvArea = std::abs(e1.x * e2.y - e1.y * e2.x) * uvScale;
  if (!(worldArea > 0.0f) || !(uvArea > 0.0f)) return sampleTexture(base, at);
  const float texels =
      std::sqrt(uvArea / worldArea * float(base.width) * float(base.height)) * footprint;
  const std::vector<Texture>& chain = pyramid->levels[std::size_t(texture)];
  const float lod = std::clamp(std::log2(std::max(texels, 1.0f)), 0.0f, float(chain.size()));
  const int lower = int(std::floor(lod));
  const float f = lod - float(lower);
  auto level = [&](int k) -> const Texture& { return k == 0 ? base : chain[std::size_t(k - 1)]; };
  const glm::vec4 a = sampleTexture(level(lower), at);
  if (f <= 0.0f || lower >= int(chain.size())) return a;
  return glm::mix(a, sampleTexture(level(lower + 1), at), f);
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
  if (auto tap =
          sampleSlot(scene, triangle, bary, m.baseColorTexture, m.baseColorTexCoord, m.baseColorUv))
    color *= *tap;
  return color;
}

glm::vec3 sampleEmission(const TriangleScene& scene, std::uint32_t triangle, glm::vec2 bary) {
  const Material& m = materialOf(scene, triangle);
  glm::vec3 emission = m.emissive;
  if (emission == glm::vec3(0.0f)) return emission;
  if (auto tap =
          sampleSlot(scene, triangle, bary, m.emissiveTexture, m.emissiveTexCoord, m.emissiveUv))
    emission *= glm::vec3(*tap);
  return emission;
}

TexturePyramid buildTexturePyramid(const TriangleScene& scene) {
  const auto& lut = srgbToLinearTable();
  TexturePyramid pyramid;
  pyramid.levels.resize(scene.textures.size());
  for (std::size_t t = 0; t < scene.textures.size(); ++t) {
    const Texture* above = &scene.textures[t];
    if (above->width <= 0 || above->height <= 0 ||
        above->rgba.size() != std::size_t(above->width) * std::size_t(above->height) * 4)
      continue;  // sampleTexture treats it as white at every level
    std::vector<Texture>& chain = pyramid.levels[t];
    while (above->width > 1 || above->height > 1) {
      Texture next;
      next.width = std::max(above->width / 2, 1);
      next.height = std::max(above->height / 2, 1);
      next.rgba.resize(std::size_t(next.width) * std::size_t(next.height) * 4);
      for (int y = 0; y < next.height; ++y)
        for (int x = 0; x < next.width; ++x) {
          glm::vec4 sum(0.0f);
          // The 2x2 block above (one texel along an axis that was already 1 wide).
          for (int dy = 0; dy < 2; ++dy)
            for (int dx = 0; dx < 2; ++dx) {
              const int sx = std::min(2 * x + dx, above->width - 1);
              const int sy = std::min(2 * y + dy, above->height - 1);
              const std::uint8_t* texel =
                  &above->rgba[(std::size_t(sy) * std::size_t(above->width) + std::size_t(sx)) * 4];
              sum += glm::vec4(lut[texel[0]], lut[texel[1]], lut[texel[2]], texel[3] / 255.0f);
            }
          sum *= 0.25f;
          std::uint8_t* out =
              &next.rgba[(std::size_t(y) * std::size_t(next.width) + std::size_t(x)) * 4];
          for (int c = 0; c < 3; ++c) {
            const double v = sum[c];
            const double e = v <= 0.0031308 ? 12.92 * v : 1.055 * std::pow(v, 1.0 / 2.4) - 0.055;
            out[c] = std::uint8_t(std::lround(std::clamp(e, 0.0, 1.0) * 255.0));
          }
          out[3] = std::uint8_t(std::lround(std::clamp(sum.a, 0.0f, 1.0f) * 255.0f));
        }
      chain.push_back(std::move(next));
      above = &chain.back();
    }
  }
  return pyramid;
}

glm::vec4 sampleAlbedo(const TriangleScene& scene, const TexturePyramid& pyramid,
                       std::uint32_t triangle, glm::vec2 bary, float footprint) {
  const Material& m = materialOf(scene, triangle);
  glm::vec4 color = m.baseColorFactor;
  if (auto tap = sampleSlot(scene, triangle, bary, m.baseColorTexture, m.baseColorTexCoord,
                            m.baseColorUv, &pyramid, footprint))
    color *= *tap;
  return color;
}

glm::vec3 sampleEmission(const TriangleScene& scene, const TexturePyramid& pyramid,
                         std::uint32_t triangle, glm::vec2 bary, float footprint) {
  const Material& m = materialOf(scene, triangle);
  glm::vec3 emission = m.emissive;
  if (emission == glm::vec3(0.0f)) return emission;
  if (auto tap = sampleSlot(scene, triangle, bary, m.emissiveTexture, m.emissiveTexCoord,
                            m.emissiveUv, &pyramid, footprint))
    emission *= glm::vec3(*tap);
  return emission;
}

}  // namespace sdfstream
