// The depth blend's ray lists (gi/probe_depth_lists.h) against the dense blend they replace: the
// same moments from the listed rays alone, within the weight the lists leave out.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <vector>

#include <gtest/gtest.h>
#include <glm/gtc/type_ptr.hpp>

#include "gi/probe_depth_lists.h"
#include "gi/probe_math.h"

namespace sdfstream::probe {
namespace {

using gpu_shared::kProbeDepthInterior;
using gpu_shared::kProbeDepthListDense;
using gpu_shared::kProbeDepthListRays;
using gpu_shared::kProbeDepthListVec4s;

struct Listed {
  std::uint32_t ray;
  float weight;
};

// Texel t's list, or nothing with dense = true.
std::vector<Listed> listOf(const std::vector<glm::vec4>& lists, std::uint32_t t, bool& dense) {
  const float* block = glm::value_ptr(lists[std::size_t(t) * kProbeDepthListVec4s]);
  const std::uint32_t count = glm::floatBitsToUint(block[0]);
  dense = count == kProbeDepthListDense;
  std::vector<Listed> out;
  if (dense) return out;
  for (std::uint32_t e = 0; e < count; ++e)
    out.push_back({glm::floatBitsToUint(block[4 + 2 * e]), block[4 + 2 * e + 1]});
  return out;
}

// Mean depth of a texel: every ray (the dense blend) or the listed ones.
float denseMean(glm::vec3 texelDir, const std::vector<glm::vec3>& dirs,
                const std::vector<float>& depth, float sharpness) {
  double wd = 0.0, w = 0.0;
  for (std::size_t r = 0; r < dirs.size(); ++r) {
    const double k = depthWeight(texelDir, dirs[r], sharpness);
    wd += k * depth[r];
    w += k;
  }
  return float(wd / w);
}

TEST(ProbeDepthLists, ListedRaysGiveTheDenseBlendsMoments) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> depthOf(0.5f, 40.0f);
  float worst = 0.0f;
  std::uint32_t most = 0, total = 0, texels = 0;
  for (std::uint32_t rays : {32u, 128u, 256u}) {
    for (std::uint32_t pattern = 0; pattern < 4; ++pattern) {
      const glm::mat3 rotation = randomRotation(0xdee9u + pattern);
      std::vector<glm::vec4> lists;
      appendDepthRayLists(rotation, rays, gpu_shared::kProbeDepthSharpness, lists);
      ASSERT_EQ(lists.size(),
                std::size_t(kProbeDepthInterior) * kProbeDepthInterior * kProbeDepthListVec4s);
      std::vector<glm::vec3> dirs(rays);
      std::vector<float> depth(rays);
      for (std::uint32_t r = 0; r < rays; ++r) {
        dirs[r] = rayDirection(r, rays, rotation);
        depth[r] = depthOf(rng);
      }
      for (std::uint32_t t = 0; t < kProbeDepthInterior * kProbeDepthInterior; ++t) {
        const glm::vec3 texelDir = texelDirection(
            glm::uvec2(t % kProbeDepthInterior, t / kProbeDepthInterior), kProbeDepthInterior);
        bool dense = false;
        const std::vector<Listed> list = listOf(lists, t, dense);
        ASSERT_FALSE(dense) << rays << " rays, texel " << t;  // sharpness 50 fits every list
        ASSERT_GE(list.size(), 1u) << rays << " rays, texel " << t;
        double wd = 0.0, w = 0.0;
        for (std::size_t e = 0; e < list.size(); ++e) {
          ASSERT_LT(list[e].ray, rays);
          if (e > 0) {
            ASSERT_LT(list[e - 1].ray, list[e].ray);  // ray order, as the dense sums
          }
          EXPECT_EQ(list[e].weight,
                    depthWeight(texelDir, dirs[list[e].ray], gpu_shared::kProbeDepthSharpness));
          wd += double(list[e].weight) * depth[list[e].ray];
          w += list[e].weight;
        }
        const float dense0 = denseMean(texelDir, dirs, depth, gpu_shared::kProbeDepthSharpness);
        worst = std::max(worst, std::abs(float(wd / w) / dense0 - 1.0f));
        most = std::max(most, std::uint32_t(list.size()));
        total += std::uint32_t(list.size());
        ++texels;
      }
    }
  }
  std::printf(
      "[figures] depth ray lists at sharpness 50 (32, 128, 256 rays, 4 patterns each): "
      "mean %.1f rays a texel, most %u of %u; worst mean depth against every ray %.2e\n",
      double(total) / texels, most, kProbeDepthListRays, worst);
  EXPECT_LT(worst, 1e-3f);
}

TEST(ProbeDepthLists, ATexelWithTooManyRaysBlendsThemAll) {
  // Sharpness 2 is a wide lobe: most of 256 rays count, far more than a list holds.
  std::vector<glm::vec4> lists;
  appendDepthRayLists(randomRotation(3), 256, 2.0f, lists);
  std::uint32_t dense = 0;
  for (std::uint32_t t = 0; t < kProbeDepthInterior * kProbeDepthInterior; ++t) {
    bool isDense = false;
    listOf(lists, t, isDense);
    dense += isDense ? 1u : 0u;
  }
  EXPECT_EQ(dense, kProbeDepthInterior * kProbeDepthInterior);
}

}  // namespace
}  // namespace sdfstream::probe
