// A cascade stack built straight from an analytic signed distance function (no pack): each
// cascade c (voxel 2^c cascade-0 voxels, windows centred on the same point) samples the function
// at its brick samples; pages within the narrow band become resident bricks with uniform
// material, the others carry a conservative "no surface within" bound (or 0 inside solid). For
// probe and light tests that need exact geometry and exact answers.
#pragma once

#include <algorithm>
#include <cmath>
#include <functional>
#include <vector>

#include <glm/gtc/packing.hpp>

#include "streaming/cascade_stack.h"

namespace sdfstream::test {

struct AnalyticStack {
  // (position, cascade voxel size): cascade-0 voxels, + in empty space. The voxel size lets a
  // scene thicken thin walls in coarse cascades as the importer's min-filter LOD chain does.
  using Sdf = std::function<float(glm::vec3, float)>;
  using Material = std::function<glm::uvec2(glm::vec3)>;     // (albedo RGBA8, emission RGB9E5)
  std::vector<std::uint32_t> distance, albedo, emission;
  CascadeStackImage image;

  // `centre`: the windows' common centre (cascade-0 voxels from cascade 0's min corner, so
  // (64,64,64) for a centred stack).
  AnalyticStack(int cascades, const Sdf& sdf, const Material& material,
                glm::vec3 centre = glm::vec3(64.0f)) {
    std::uint32_t slot = 0;
    for (int c = 0; c < cascades; ++c) {
      const float scale = float(1 << c);
      const glm::vec3 offset = centre - glm::vec3(64.0f * scale);
      gpu_shared::CascadeTraceParams p{};
      p.offsetScale = glm::vec4(offset, scale);
      p.toroidal = glm::uvec4(0u, 0u, 0u, std::uint32_t(c) * gpu_shared::kCascadePageCount);
      image.params.push_back(p);
      image.originBricks.push_back(glm::ivec3(glm::floor(offset / (8.0f * scale))));
      for (int pz = 0; pz < 16; ++pz)
        for (int py = 0; py < 16; ++py)
          for (int px = 0; px < 16; ++px) {
            float samples[730] = {};
            float minAbs = 1e30f, minValue = 1e30f;
            for (int z = 0; z < 9; ++z)
              for (int y = 0; y < 9; ++y)
                for (int x = 0; x < 9; ++x) {
                  const glm::vec3 q = offset + (glm::vec3(px, py, pz) * 8.0f + glm::vec3(x, y, z)) * scale;
                  const float d = sdf(q, scale) / scale;  // in this cascade's voxels
                  samples[x + 9 * (y + 9 * z)] = std::clamp(d, -gpu_shared::kNarrowBand, gpu_shared::kNarrowBand);
                  minAbs = std::min(minAbs, std::abs(d));
                  minValue = std::min(minValue, d);
                }
            std::uint32_t entry = 0;
            if (minAbs <= gpu_shared::kNarrowBand + 1.0f) {
              entry = gpu_shared::kPageResidentBit | slot;
              for (std::uint32_t w = 0; w < gpu_shared::kBrickDistanceWords; ++w)
                distance.push_back(glm::packHalf2x16(glm::vec2(samples[2 * w], samples[2 * w + 1])));
              for (int cell = 0; cell < 512; ++cell) {
                const glm::vec3 q = offset + (glm::vec3(px, py, pz) * 8.0f +
                                              glm::vec3(cell % 8, cell / 8 % 8, cell / 64) + 0.5f) * scale;
                const glm::uvec2 m = material(q);
                albedo.push_back(m.x);
                emission.push_back(m.y);
              }
              ++slot;
            } else if (minValue > 0.0f) {
              // Empty page: every point is at least minValue - (half a page diagonal) away;
              // samples bound the distance only at sample points, so stay a voxel short.
              entry = std::uint32_t(std::max(0.0f, std::floor(minValue - 1.0f)));
            }
            image.pageTables.push_back(entry);
          }
    }
    image.distanceAtlas = &distance;
    image.albedoAtlas = &albedo;
    image.emissionAtlas = &emission;
    image.voxelSize0 = 1.0;
  }
  AnalyticStack(const AnalyticStack&) = delete;  // image points into this object
  AnalyticStack& operator=(const AnalyticStack&) = delete;
};

inline glm::uvec2 uniformMaterial(std::uint32_t albedoRgba8, std::uint32_t emissionRgb9e5) {
  return glm::uvec2(albedoRgba8, emissionRgb9e5);
}

}  // namespace sdfstream::test
