// Small shared helpers of the probe field tests: comparisons, random queries, analytic SDFs.
#pragma once

#include <algorithm>
#include <cmath>
#include <random>
#include <span>
#include <vector>

#include <gtest/gtest.h>

#include "gi/probe_math.h"
#include "shaders/shared/probe_layout.h"
#include "streaming/cascade_stack.h"
#include "tests/support/analytic_stack.h"

namespace sdfstream::test {

// Largest |a - b| / max(|a|, |b|, floor) over all components (floor keeps near-zero values from
// dominating with pure rounding noise); a NaN or Inf counts as 1e30.
template <typename V, int N>
float worstRelative(std::span<const V> a, std::span<const V> b, float floor) {
  EXPECT_EQ(a.size(), b.size());
  float worst = 0.0f;
  for (std::size_t i = 0; i < std::min(a.size(), b.size()); ++i)
    for (int c = 0; c < N; ++c) {
      const float x = a[i][c], y = b[i][c];
      const float rel = std::abs(x - y) / std::max({std::abs(x), std::abs(y), floor});
      if (!(rel <= worst)) worst = std::isfinite(rel) ? rel : 1e30f;
    }
  return worst;
}
template <typename V, int N>
float worstRelative(const std::vector<V>& a, const std::vector<V>& b, float floor) {
  return worstRelative<V, N>(std::span<const V>(a), std::span<const V>(b), floor);
}

inline glm::vec3 randomUnit(std::mt19937& rng) {
  std::normal_distribution<float> g;
  const glm::vec3 d(g(rng), g(rng), g(rng));
  return glm::length(d) > 1e-3f ? glm::normalize(d) : glm::vec3(0.0f, 0.0f, 1.0f);
}

// Queries at random points of cascade `c`'s window shrunk by `margin` cascade-0 voxels, random
// normals and view directions.
inline std::vector<gpu_shared::ProbeQuery> randomQueries(const CascadeStackImage& img, int c,
                                                         int count, std::uint32_t seed,
                                                         float margin = 0.0f) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  const glm::vec4 p = img.params[c].offsetScale;
  const glm::vec3 lo = glm::vec3(p) + glm::vec3(margin);
  const glm::vec3 size = glm::vec3(128.0f * p.w - 2.0f * margin);
  std::vector<gpu_shared::ProbeQuery> q(count);
  for (auto& x : q) {
    x.position = glm::vec4(lo + size * glm::vec3(u(rng), u(rng), u(rng)), 0.0f);
    x.normal = glm::vec4(randomUnit(rng), 0.0f);
    x.view = glm::vec4(randomUnit(rng), 0.0f);
  }
  return q;
}

// Receivers on the inner faces of the box [lo, hi] (half a voxel in front of a random face,
// normal pointing into the box), random view directions on the normal's side.
inline std::vector<gpu_shared::ProbeQuery> boxWallQueries(glm::vec3 lo, glm::vec3 hi, int count,
                                                          std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  std::vector<gpu_shared::ProbeQuery> q(count);
  for (int i = 0; i < count; ++i) {
    const int face = i % 6, axis = face / 2;
    glm::vec3 p = lo + (hi - lo) * glm::vec3(u(rng), u(rng), u(rng));
    glm::vec3 n(0.0f);
    n[axis] = face % 2 == 0 ? 1.0f : -1.0f;
    p[axis] = face % 2 == 0 ? lo[axis] + 0.5f : hi[axis] - 0.5f;
    glm::vec3 v = randomUnit(rng);
    if (glm::dot(v, n) < 0.0f) v = -v;
    q[i].position = glm::vec4(p, 0.0f);
    q[i].normal = glm::vec4(n, 0.0f);
    q[i].view = glm::vec4(v, 0.0f);
  }
  return q;
}

// Mean decoded irradiance of global probe g's 36 interior texels.
inline glm::vec3 meanProbeIrradiance(std::span<const glm::vec4> atlas, std::uint32_t g, float gamma) {
  constexpr std::uint32_t t = gpu_shared::kProbeIrradianceTexels;
  glm::vec3 sum(0.0f);
  for (std::uint32_t y = 1; y <= gpu_shared::kProbeIrradianceInterior; ++y)
    for (std::uint32_t x = 1; x <= gpu_shared::kProbeIrradianceInterior; ++x)
      sum += probe::decodeIrradiance(glm::vec3(atlas[std::size_t(g) * t * t + y * t + x]), gamma);
  return sum / float(gpu_shared::kProbeIrradianceInterior * gpu_shared::kProbeIrradianceInterior);
}
inline glm::vec3 meanProbeIrradiance(const std::vector<glm::vec4>& atlas, std::uint32_t g, float gamma) {
  return meanProbeIrradiance(std::span<const glm::vec4>(atlas), g, gamma);
}

// Signed distance of the empty inside of the box [lo, hi] (positive inside, negative in the
// solid around it).
inline auto insideBox(glm::vec3 lo, glm::vec3 hi) {
  return [=](glm::vec3 p, float = 1.0f) {
    const glm::vec3 centre = 0.5f * (lo + hi), half = 0.5f * (hi - lo);
    const glm::vec3 q = glm::abs(p - centre) - half;
    const float box = glm::length(glm::max(q, glm::vec3(0.0f))) +
                      std::min(std::max(q.x, std::max(q.y, q.z)), 0.0f);
    return -box;
  };
}

// The white furnace: one cascade whose box [4, 124]³ has Lambertian walls of albedo rho (sRGB
// byte 188) that emit radiance Le = 1. In steady state the radiance is uniform, L = Le / (1 -
// rho), so every irradiance inside is pi Le / (1 - rho) (`expected`).
struct WhiteFurnaceBox {
  static constexpr std::uint32_t kSrgbByte = 188;
  static constexpr std::uint32_t kAlbedo =
      kSrgbByte | kSrgbByte << 8 | kSrgbByte << 16 | 255u << 24;
  static constexpr std::uint32_t kEmission = 256u | 256u << 9 | 256u << 18 | 16u << 27;  // 1.0
  glm::vec3 lo{4.0f}, hi{124.0f};
  double rho = std::pow((kSrgbByte / 255.0 + 0.055) / 1.055, 2.4);
  double expected = 3.141592653589793 / (1.0 - rho);
  AnalyticStack stack{1, insideBox(lo, hi),
                      [](glm::vec3) { return glm::uvec2(kAlbedo, kEmission); }};
};

}  // namespace sdfstream::test
