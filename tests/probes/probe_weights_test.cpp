// Sampling weights and small helpers of the probe math: Chebyshev visibility, backface (wrap),
// trilinear, self-shadow bias (Majercik 2021 Sec. 4.1 Eq. 2), crush, encoding, hysteresis.
#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "gi/probe_math.h"

namespace sdfstream::probe {
namespace {

constexpr float kMinVar = gpu_shared::kProbeMinVariance;

TEST(Chebyshev, OneWhenCloserThanTheMeanFallingOffBeyond) {
  const float mean = 10.0f, sigma = 2.0f;
  const glm::vec2 moments(mean, mean * mean + sigma * sigma);
  for (float r : {0.0f, 3.0f, 9.99f, 10.0f}) EXPECT_EQ(chebyshevWeight(moments, r, kMinVar), 1.0f);
  float previous = 1.0f;
  for (float k = 0.25f; k <= 6.0f; k += 0.25f) {
    const float w = chebyshevWeight(moments, mean + k * sigma, kMinVar);
    const float bound = 1.0f / (1.0f + k * k);  // one-tailed Chebyshev: var / (var + d²)
    EXPECT_NEAR(w, bound * bound * bound, 1e-5f) << k;
    EXPECT_LT(w, previous) << k;
    previous = w;
  }
  EXPECT_LT(chebyshevWeight(moments, mean + 6.0f * sigma, kMinVar), 1e-4f);
}

TEST(Chebyshev, VarianceClampKeepsConvergedWallsFiniteAndSharp) {
  // A converged texel looking at one wall: variance 0, or slightly negative from float rounding.
  const float mean = 7.0f;
  for (glm::vec2 m : {glm::vec2(mean, mean * mean), glm::vec2(mean, mean * mean - 1e-3f)}) {
    const float behind = chebyshevWeight(m, mean + 1.0f, kMinVar);
    EXPECT_TRUE(std::isfinite(behind));
    EXPECT_GE(behind, 0.0f);
    EXPECT_LT(behind, 1e-9f);  // one voxel behind the wall: occluded
    EXPECT_EQ(chebyshevWeight(m, mean, kMinVar), 1.0f);
    EXPECT_GT(chebyshevWeight(m, mean + 0.002f, kMinVar), 0.5f);  // within the clamp: visible
  }
}

TEST(BackfaceWeight, WrapCurve) {
  const glm::vec3 n(0, 0, 1);
  EXPECT_NEAR(backfaceWeight({0, 0, 1}, n), 1.2f, 1e-6f);
  EXPECT_NEAR(backfaceWeight({1, 0, 0}, n), 0.45f, 1e-6f);
  EXPECT_NEAR(backfaceWeight({0, 0, -1}, n), 0.2f, 1e-6f);
}

TEST(TrilinearWeight, PartitionOfUnity) {
  std::mt19937 rng(5u);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  for (int i = 0; i < 1000; ++i) {
    const glm::vec3 a(u(rng), u(rng), u(rng));
    float sum = 0.0f;
    for (std::uint32_t c = 0; c < 8; ++c) sum += trilinearWeight(a, c);
    ASSERT_NEAR(sum, 1.0f, 1e-5f);
  }
  EXPECT_EQ(trilinearWeight({0, 0, 0}, 0), 1.0f);
  EXPECT_EQ(trilinearWeight({1, 1, 1}, 7), 1.0f);
  EXPECT_NEAR(trilinearWeight({0.25f, 0.5f, 1.0f}, 0b101), 0.25f * 0.5f * 1.0f, 1e-6f);
}

// Eq. 2 of Majercik 2021: (n * 0.2 + view * 0.8) * (0.75 * D) * B; D = 8 cells, B = 0.3.
TEST(SelfShadowBias, MajercikEquation2) {
  const float d = static_cast<float>(gpu_shared::kProbeSpacingCells);
  const float b = gpu_shared::kProbeDefaultSelfShadowBias;
  const glm::vec3 head = selfShadowBias({0, 0, 1}, {0, 0, 1}, d, b);
  EXPECT_NEAR(head.z, 1.8f, 1e-5f);  // 0.75 * 8 * 0.3
  const glm::vec3 side = selfShadowBias({1, 0, 0}, {0, 1, 0}, d, b);
  EXPECT_NEAR(side.x, 0.2f * 1.8f, 1e-5f);
  EXPECT_NEAR(side.y, 0.8f * 1.8f, 1e-5f);
  EXPECT_NEAR(side.z, 0.0f, 1e-6f);
}

TEST(CrushWeight, ContinuousAndCubicBelowThreshold) {
  EXPECT_NEAR(crushWeight(0.2f, 0.2f), 0.2f, 1e-7f);
  EXPECT_NEAR(crushWeight(0.19999f, 0.2f), 0.2f, 1e-4f);
  EXPECT_NEAR(crushWeight(0.1f, 0.2f), 0.001f / 0.04f, 1e-7f);
  EXPECT_EQ(crushWeight(0.7f, 0.2f), 0.7f);
}

TEST(PerceptualEncoding, GammaFiveRoundTrip) {
  for (float e : {0.0f, 1e-4f, 0.5f, 1.0f, 3.14159f, 250.0f}) {
    const glm::vec3 s = encodeIrradiance(glm::vec3(e), 5.0f);
    EXPECT_NEAR(s.x, std::pow(e, 0.2f), 1e-6f);
    EXPECT_NEAR(decodeIrradiance(s, 5.0f).x, e, 1e-5f * std::max(1.0f, e));
  }
  EXPECT_EQ(encodeIrradiance(glm::vec3(-1.0f), 5.0f).x, 0.0f);  // negative input clamps
}

TEST(Hysteresis, BlendAndChangeHeuristic) {
  const glm::vec3 v = hysteresisBlend(glm::vec3(1.0f), glm::vec3(0.0f), 0.97f);
  EXPECT_NEAR(v.x, 0.97f, 1e-6f);
  EXPECT_EQ(adjustHysteresis(glm::vec3(1.0f), glm::vec3(1.1f), 0.97f), 0.97f);           // 9%
  EXPECT_NEAR(adjustHysteresis(glm::vec3(1.0f), glm::vec3(0.6f), 0.97f), 0.82f, 1e-6f);  // 40%
  EXPECT_EQ(adjustHysteresis(glm::vec3(1.0f), glm::vec3(0.1f), 0.97f), 0.0f);            // 90%
}

TEST(RayDepth, MissesAndBackfaces) {
  EXPECT_EQ(rayDepth(5.0f, false, false, 100.0f, 0.2f), 100.0f);
  EXPECT_EQ(rayDepth(5.0f, true, false, 100.0f, 0.2f), 5.0f);
  EXPECT_NEAR(rayDepth(5.0f, true, true, 100.0f, 0.2f), 1.0f, 1e-6f);
  EXPECT_EQ(rayDepth(500.0f, true, false, 100.0f, 0.2f), 100.0f);
}

}  // namespace
}  // namespace sdfstream::probe
