// Scenes for the probe update tests (the streamed bunny is tests/support/streamed_bunny.h):
// an analytic closed box built straight into a CascadeStackImage (no pack): cascade 0 holds the exact SDF of the inside of an axis-aligned box
// (positive = empty inside, negative in the walls) with uniform albedo and emission.
#pragma once

#include <cmath>
#include <filesystem>
#include <memory>
#include <vector>

#include <glm/gtc/packing.hpp>

#include "streaming/cascade_stack.h"
#include "streaming/pack_store.h"
#include "streaming/tile_loader.h"
#include "tests/support/streamed_bunny.h"
#include "tests/support/test_data.h"
#include "world/pack_import.h"

namespace sdfstream::test {

// One-cascade stack image of the inside of the box [lo, hi]³ (cascade-0 voxels, inside [0,128)).
// Pages touching the box are resident bricks; all others are "no surface, bound 0".
struct AnalyticBox {
  std::vector<std::uint32_t> distance, albedo, emission;
  CascadeStackImage image;

  AnalyticBox(float lo, float hi, std::uint32_t albedoRgba8, std::uint32_t emissionRgb9e5) {
    const int firstPage = std::max(0, int(std::floor((lo - 4.0f) / 8.0f)));
    const int endPage = std::min(16, int(std::ceil((hi + 4.0f) / 8.0f)));
    const glm::vec3 centre(0.5f * (lo + hi)), half(0.5f * (hi - lo));
    image.pageTables.assign(gpu_shared::kCascadePageCount, 0u);
    std::uint32_t slot = 0;
    for (int pz = firstPage; pz < endPage; ++pz)
      for (int py = firstPage; py < endPage; ++py)
        for (int px = firstPage; px < endPage; ++px, ++slot) {
          image.pageTables[px + 16 * (py + 16 * pz)] = gpu_shared::kPageResidentBit | slot;
          distance.resize(std::size_t(slot + 1) * gpu_shared::kBrickDistanceWords, 0u);
          float samples[730] = {};
          for (int z = 0; z < 9; ++z)
            for (int y = 0; y < 9; ++y)
              for (int x = 0; x < 9; ++x) {
                const glm::vec3 p = glm::vec3(px, py, pz) * 8.0f + glm::vec3(x, y, z);
                const glm::vec3 q = glm::abs(p - centre) - half;  // sdBox of the solid box
                const float box = glm::length(glm::max(q, glm::vec3(0.0f))) +
                                  std::min(std::max(q.x, std::max(q.y, q.z)), 0.0f);
                samples[x + 9 * (y + 9 * z)] =
                    glm::clamp(-box, -gpu_shared::kNarrowBand, gpu_shared::kNarrowBand);
              }
          for (std::uint32_t w = 0; w < gpu_shared::kBrickDistanceWords; ++w)
            distance[slot * gpu_shared::kBrickDistanceWords + w] =
                glm::packHalf2x16(glm::vec2(samples[2 * w], samples[2 * w + 1]));
        }
    albedo.assign(std::size_t(slot) * gpu_shared::kBrickMaterialCount, albedoRgba8);
    emission.assign(std::size_t(slot) * gpu_shared::kBrickMaterialCount, emissionRgb9e5);
    image.distanceAtlas = &distance;
    image.albedoAtlas = &albedo;
    image.emissionAtlas = &emission;
    gpu_shared::CascadeTraceParams params{};
    params.offsetScale = glm::vec4(0.0f, 0.0f, 0.0f, 1.0f);
    params.toroidal = glm::uvec4(0u);
    image.params = {params};
    image.voxelSize0 = 1.0;
  }
  AnalyticBox(const AnalyticBox&) = delete;  // image points into this object
  AnalyticBox& operator=(const AnalyticBox&) = delete;
};

}  // namespace sdfstream::test
