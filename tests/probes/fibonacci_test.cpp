// Ray directions: the spherical Fibonacci set and the per-frame random rotation are uniform on
// the sphere (pbrt-style statistical tests with fixed seeds).
#include <array>
#include <cmath>
#include <cstdio>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "gi/probe_math.h"

namespace sdfstream::probe {
namespace {

constexpr float kPi = 3.14159265358979f;

// 12 equal-area bins: 3 bands of equal z-range (equal area, Archimedes) x 4 azimuth sectors.
int equalAreaBin(glm::vec3 d) {
  const int band = glm::clamp(static_cast<int>((d.z + 1.0f) * 1.5f), 0, 2);
  const float phi = std::atan2(d.y, d.x) + kPi;  // [0, 2pi]
  const int sector = glm::clamp(static_cast<int>(phi / (0.5f * kPi)), 0, 3);
  return band * 4 + sector;
}

double chiSquare(const std::array<int, 12>& counts, int total) {
  const double expected = total / 12.0;
  double chi2 = 0.0;
  for (int c : counts) chi2 += (c - expected) * (c - expected) / expected;
  return chi2;
}

// chi² with 11 degrees of freedom exceeds 31.26 with probability 0.001.
constexpr double kChi2Critical11 = 31.26;

TEST(SphericalFibonacci, UnitLengthAndMeanNearZero) {
  for (std::uint32_t n : {64u, 128u, 256u}) {
    glm::vec3 mean(0.0f);
    for (std::uint32_t i = 0; i < n; ++i) {
      const glm::vec3 d = sphericalFibonacci(i, n);
      ASSERT_NEAR(glm::length(d), 1.0f, 1e-5f);
      mean += d;
    }
    mean /= static_cast<float>(n);
    std::printf("[ measure  ] fibonacci n=%u: |mean direction| = %.2e\n", n, glm::length(mean));
    EXPECT_LT(glm::length(mean), 2.0f / static_cast<float>(n));
  }
}

TEST(SphericalFibonacci, EqualAreaBinsChiSquare) {
  const std::uint32_t n = 1200;
  std::array<int, 12> counts{};
  for (std::uint32_t i = 0; i < n; ++i) ++counts[equalAreaBin(sphericalFibonacci(i, n))];
  const double chi2 = chiSquare(counts, n);
  std::printf("[ measure  ] fibonacci n=%u: chi2 over 12 equal-area bins = %.3f\n", n, chi2);
  // A low-discrepancy set sits far below the random-sampling critical value.
  EXPECT_LT(chi2, 2.0);
}

// Every hemisphere (random axis, fixed seed) holds half of a rotated 128-ray set, to within the
// few points that straddle the boundary.
TEST(SphericalFibonacci, HemispheresHoldHalfOfTheRays) {
  const std::uint32_t n = gpu_shared::kProbeDefaultRays;
  std::mt19937 rng(3u);
  std::normal_distribution<float> g;
  int worst = 0;
  for (int frame = 0; frame < 200; ++frame) {
    const glm::mat3 rotation = randomRotation(1000u + frame);
    const glm::vec3 axis = glm::normalize(glm::vec3(g(rng), g(rng), g(rng)));
    int inside = 0;
    for (std::uint32_t i = 0; i < n; ++i)
      inside += glm::dot(rayDirection(i, n, rotation), axis) > 0.0f;
    worst = std::max(worst, std::abs(inside - static_cast<int>(n / 2)));
  }
  std::printf("[ measure  ] 200 hemispheres of 128 rays: worst |count - 64| = %d\n", worst);
  EXPECT_LE(worst, 6);
}

// Quadrature: (4 pi / n) * sum max(0, t.d_i) ~ integral of max(0, cos) = pi, for every
// irradiance texel direction t. This is what the cosine-weighted blend relies on.
TEST(SphericalFibonacci, CosineQuadratureMatchesPi) {
  const std::uint32_t n = gpu_shared::kProbeDefaultRays;
  float worst = 0.0f;
  constexpr std::uint32_t kInterior = gpu_shared::kProbeIrradianceInterior;
  for (std::uint32_t y = 0; y < kInterior; ++y) {
    for (std::uint32_t x = 0; x < kInterior; ++x) {
      const glm::vec3 t = texelDirection({x, y}, kInterior);
      float sum = 0.0f;
      for (std::uint32_t i = 0; i < n; ++i) sum += irradianceWeight(t, sphericalFibonacci(i, n));
      const float estimate = 4.0f * kPi / static_cast<float>(n) * sum;
      worst = std::max(worst, std::abs(estimate / kPi - 1.0f));
    }
  }
  std::printf("[ measure  ] cosine quadrature, 128 fibonacci rays: worst relative error %.4f\n",
              worst);
  EXPECT_LT(worst, 0.01f);
}

TEST(RandomRotation, IsARotationAndDeterministic) {
  for (std::uint64_t seed = 0; seed < 100; ++seed) {
    const glm::mat3 r = randomRotation(seed);
    const glm::mat3 rtr = glm::transpose(r) * r;
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) ASSERT_NEAR(rtr[i][j], i == j ? 1.0f : 0.0f, 1e-5f);
    ASSERT_NEAR(glm::determinant(r), 1.0f, 1e-5f);
    const glm::mat3 again = randomRotation(seed);
    for (int i = 0; i < 3; ++i) ASSERT_EQ(r[i], again[i]);
  }
  EXPECT_NE(randomRotation(1)[0], randomRotation(2)[0]);
}

// Uniform over SO(3) => a fixed vector rotated by random rotations is uniform on the sphere.
TEST(RandomRotation, RotatedPoleIsUniformChiSquare) {
  const int samples = 12000;
  std::array<int, 12> counts{};
  for (int s = 0; s < samples; ++s) ++counts[equalAreaBin(randomRotation(s) * glm::vec3(0, 0, 1))];
  const double chi2 = chiSquare(counts, samples);
  std::printf("[ measure  ] rotated pole, %d seeds: chi2 = %.2f (critical %.2f at p=0.001)\n",
              samples, chi2, kChi2Critical11);
  EXPECT_LT(chi2, kChi2Critical11);
  // Control: the unrotated Fibonacci pole (always +z) lands in one band and fails.
  std::array<int, 12> biased{};
  for (int s = 0; s < samples; ++s) ++biased[equalAreaBin(sphericalFibonacci(0, 128))];
  EXPECT_GT(chiSquare(biased, samples), kChi2Critical11);
}

}  // namespace
}  // namespace sdfstream::probe
