// Analytic one-cascade scenes and light helpers for the light cache tests. A scene is an exact SDF
// (cascade-0 voxels, negative inside solids) sampled straight into a CascadeStackImage, as the
// importer would: a page is a resident brick when any of its 9³ samples lies inside the narrow
// band, otherwise an empty page with a conservative distance bound.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <functional>
#include <limits>
#include <utility>
#include <vector>

#include <glm/glm.hpp>
#include <glm/gtc/packing.hpp>

#include "shaders/shared/color_codec.h"
#include "shaders/shared/light_layout.h"
#include "streaming/cascade_stack.h"

namespace sdfstream::test {

// Exact signed distance to the solid box [lo, hi] (negative inside).
inline float sdBox(glm::vec3 p, glm::vec3 lo, glm::vec3 hi) {
  const glm::vec3 q = glm::abs(p - 0.5f * (lo + hi)) - 0.5f * (hi - lo);
  return glm::length(glm::max(q, glm::vec3(0.0f))) +
         std::min(std::max(q.x, std::max(q.y, q.z)), 0.0f);
}

// The floor every scene stands on: a slab y in [30, 40] across the whole cascade (top at y = 40).
inline float sdFloor(glm::vec3 p) { return sdBox(p, {-64, 30, -64}, {192, 40, 192}); }
constexpr float kFloorTop = 40.0f;

inline float srgbToLinear(float c) {
  return c <= 0.04045f ? c / 12.92f : std::pow((c + 0.055f) / 1.055f, 2.4f);
}

struct AnalyticScene {
  using Sdf = std::function<float(glm::vec3)>;
  using Material = std::function<std::uint32_t(glm::vec3)>;  // of a cell centre

  std::vector<std::uint32_t> distance, albedo, emission;
  CascadeStackImage image;

  // cascades > 1 adds coarser cascades centred on cascade 0 (cascade c spans
  // [-64·(2^c - 1), 128 + 64·(2^c - 1)) in cascade-0 voxels, voxel 2^c), as the streamer would.
  AnalyticScene(const Sdf& sdf, const Material& albedoAt, const Material& emissionAt,
                double voxelSize = 1.0, int cascades = 1) {
    using namespace gpu_shared;
    image.pageTables.assign(std::size_t(cascades) * kCascadePageCount, 0u);
    for (int c = 0; c < cascades; ++c) {
      const float scale = float(1 << c);
      const glm::vec3 offset(-64.0f * (scale - 1.0f));
      gpu_shared::CascadeTraceParams params{};
      params.offsetScale = glm::vec4(offset, scale);
      params.toroidal = glm::uvec4(0u, 0u, 0u, std::uint32_t(c) * kCascadePageCount);
      image.params.push_back(params);
      // Positions in cascade-0 voxels; distances stored in this cascade's voxels.
      auto at = [&](glm::vec3 local) { return sdf(offset + local * scale) / scale; };
      for (int pz = 0; pz < 16; ++pz)
        for (int py = 0; py < 16; ++py)
          for (int px = 0; px < 16; ++px)
            addPage(c, glm::ivec3(px, py, pz), at, [&](glm::vec3 local) {
              return std::pair(albedoAt(offset + local * scale),
                               emissionAt(offset + local * scale));
            });
    }
    image.distanceAtlas = &distance;
    image.albedoAtlas = &albedo;
    image.emissionAtlas = &emission;
    image.voxelSize0 = voxelSize;
  }
  AnalyticScene(const Sdf& sdf, std::uint32_t albedoRgba8, std::uint32_t emissionRgb9e5 = 0,
                double voxelSize = 1.0, int cascades = 1)
      : AnalyticScene(
            sdf, [=](glm::vec3) { return albedoRgba8; }, [=](glm::vec3) { return emissionRgb9e5; },
            voxelSize, cascades) {}
  AnalyticScene(const AnalyticScene&) = delete;  // image points into this object
  AnalyticScene& operator=(const AnalyticScene&) = delete;

  template <typename Dist, typename Mat>
  void addPage(int c, glm::ivec3 page, const Dist& at, const Mat& materialAt) {
    using namespace gpu_shared;
    const glm::vec3 base = glm::vec3(page) * 8.0f;
    float samples[730] = {};
    float nearest = std::numeric_limits<float>::max();
    for (int z = 0; z < 9; ++z)
      for (int y = 0; y < 9; ++y)
        for (int x = 0; x < 9; ++x) {
          const float d = at(base + glm::vec3(x, y, z));
          nearest = std::min(nearest, std::abs(d));
          samples[x + 9 * (y + 9 * z)] = glm::clamp(d, -kNarrowBand, kNarrowBand);
        }
    const std::size_t index =
        std::size_t(c) * kCascadePageCount + std::size_t(page.x + 16 * (page.y + 16 * page.z));
    if (nearest >= kNarrowBand) {
      // |sdf| at the centre minus the half diagonal bounds every point of the page.
      const float bound = std::abs(at(base + glm::vec3(4.0f))) - 4.0f * std::sqrt(3.0f);
      image.pageTables[index] = std::uint32_t(std::max(0.0f, std::floor(bound)));
      return;
    }
    const std::uint32_t slot = std::uint32_t(distance.size() / kBrickDistanceWords);
    image.pageTables[index] = kPageResidentBit | slot;
    for (std::uint32_t w = 0; w < kBrickDistanceWords; ++w)
      distance.push_back(glm::packHalf2x16(glm::vec2(samples[2 * w], samples[2 * w + 1])));
    for (std::uint32_t cell = 0; cell < kBrickMaterialCount; ++cell) {
      const auto [a, e] = materialAt(base + cellOffset(cell));
      albedo.push_back(a);
      emission.push_back(e);
    }
  }

  static glm::vec3 cellOffset(std::uint32_t cell) {
    return glm::vec3(float(cell & 7u), float((cell >> 3) & 7u), float(cell >> 6)) + 0.5f;
  }
  // Global page index (one cascade, toroidal offset 0) of the page holding voxel v.
  static std::uint32_t pageOf(glm::ivec3 v) {
    return std::uint32_t(v.x / 8 + 16 * (v.y / 8 + 16 * (v.z / 8)));
  }

  // Atlas material index of the cell [v, v+1)³, or -1 (as uint) when its page is not resident.
  std::uint32_t materialIndex(glm::ivec3 v) const {
    const std::uint32_t entry = image.pageTables[pageOf(v)];
    if ((entry & gpu_shared::kPageResidentBit) == 0u) return ~0u;
    const glm::ivec3 c = v % 8;
    return (entry & gpu_shared::kPagePayloadMask) * gpu_shared::kBrickMaterialCount +
           std::uint32_t(c.x + 8 * (c.y + 8 * c.z));
  }

  // The same for cascade c, v in that cascade's voxels.
  std::uint32_t materialIndexIn(int c, glm::ivec3 v) const {
    const std::uint32_t entry =
        image.pageTables[std::size_t(c) * gpu_shared::kCascadePageCount + pageOf(v)];
    if ((entry & gpu_shared::kPageResidentBit) == 0u) return ~0u;
    const glm::ivec3 l = v % 8;
    return (entry & gpu_shared::kPagePayloadMask) * gpu_shared::kBrickMaterialCount +
           std::uint32_t(l.x + 8 * (l.y + 8 * l.z));
  }

  std::vector<std::uint32_t> residentPages() const {
    std::vector<std::uint32_t> out;
    for (std::uint32_t i = 0; i < image.pageTables.size(); ++i)
      if (image.pageTables[i] & gpu_shared::kPageResidentBit) out.push_back(i);
    return out;
  }
  // Resident pages among those with page coordinates in [lo, hi] (inclusive).
  std::vector<std::uint32_t> residentPagesIn(glm::ivec3 lo, glm::ivec3 hi) const {
    std::vector<std::uint32_t> out;
    for (int z = lo.z; z <= hi.z; ++z)
      for (int y = lo.y; y <= hi.y; ++y)
        for (int x = lo.x; x <= hi.x; ++x) {
          const std::uint32_t i = std::uint32_t(x + 16 * (y + 16 * z));
          if (image.pageTables[i] & gpu_shared::kPageResidentBit) out.push_back(i);
        }
    return out;
  }
};

// sRGB bytes -> the atlas's RGBA8 (alpha 255).
inline std::uint32_t rgba8(std::uint32_t r, std::uint32_t g, std::uint32_t b) {
  return r | g << 8 | b << 16 | 255u << 24;
}
inline glm::vec3 linearAlbedo(std::uint32_t rgba) {
  return glm::vec3(srgbToLinear(float(rgba & 255u) / 255.0f),
                   srgbToLinear(float((rgba >> 8) & 255u) / 255.0f),
                   srgbToLinear(float((rgba >> 16) & 255u) / 255.0f));
}

inline gpu_shared::GpuLight sunLight(glm::vec3 towardsLight, float intensity, float k = 0.0f,
                                     glm::vec3 color = glm::vec3(1.0f)) {
  gpu_shared::GpuLight l{};
  l.positionType = glm::vec4(0.0f, 0.0f, 0.0f, float(gpu_shared::kLightSun));
  l.direction = glm::vec4(glm::normalize(towardsLight), 0.0f);
  l.colorIntensity = glm::vec4(color, intensity);
  l.shape = glm::vec4(1.0f, 0.0f, k, 1.0f);
  return l;
}
inline gpu_shared::GpuLight pointLight(glm::vec3 position, float intensity,
                                       float rangeMetres = 0.0f, float k = 0.0f,
                                       glm::vec3 color = glm::vec3(1.0f)) {
  gpu_shared::GpuLight l{};
  l.positionType = glm::vec4(position, float(gpu_shared::kLightPoint));
  l.direction = glm::vec4(0.0f, -1.0f, 0.0f, -1.0f);
  l.colorIntensity = glm::vec4(color, intensity);
  l.shape = glm::vec4(1.0f, rangeMetres, k, 1.0f);
  return l;
}
inline gpu_shared::GpuLight spotLight(glm::vec3 position, glm::vec3 pointing, float innerDeg,
                                      float outerDeg, float intensity, float k = 0.0f) {
  const float toRad = 3.14159265358979f / 180.0f;
  gpu_shared::GpuLight l = pointLight(position, intensity, 0.0f, k);
  l.positionType.w = float(gpu_shared::kLightSpot);
  l.direction = glm::vec4(glm::normalize(pointing), std::cos(outerDeg * toRad));
  l.shape.x = std::cos(innerDeg * toRad);
  return l;
}

inline glm::vec3 decode(std::uint32_t rgb9e5) { return gpu_shared::unpackRgb9e5(rgb9e5); }

}  // namespace sdfstream::test
