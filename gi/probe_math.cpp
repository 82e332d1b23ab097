#include "gi/probe_math.h"

#include <cassert>
#include <cmath>
#include <random>

#include <glm/gtc/quaternion.hpp>

namespace sdfstream::probe {
namespace detail {
using namespace glm;
using namespace gpu_shared;

// The GLSL functions become member functions of a stateless struct (as in gi/cpu_tracer.cpp).
struct ProbeMath {
#include "shaders/probe_math.glsl"
};
ProbeMath gMath;  // stateless: safe to share between threads

// Bilinear read of a bordered tile, the way a GPU sampler filters it (texel centres at +0.5).
template <typename T>
T bilinear(std::span<const T> tile, std::uint32_t size, glm::vec2 coord) {
  const glm::vec2 c = coord - glm::vec2(0.5f);
  const glm::vec2 base = glm::floor(c);
  const glm::vec2 f = c - base;
  const int maxIndex = static_cast<int>(size) - 1;
  const int x0 = glm::clamp(static_cast<int>(base.x), 0, maxIndex);
  const int y0 = glm::clamp(static_cast<int>(base.y), 0, maxIndex);
  const int x1 = glm::min(x0 + 1, maxIndex);
  const int y1 = glm::min(y0 + 1, maxIndex);
  auto at = [&](int x, int y) { return tile[static_cast<std::size_t>(y) * size + x]; };
  const T a = glm::mix(at(x0, y0), at(x1, y0), f.x);
  const T b = glm::mix(at(x0, y1), at(x1, y1), f.x);
  return glm::mix(a, b, f.y);
}

template <typename T>
void copyBorders(std::span<T> tile, std::uint32_t size) {
  for (std::uint32_t y = 0; y < size; ++y) {
    for (std::uint32_t x = 0; x < size; ++x) {
      const glm::uvec2 s = gMath.probeBorderSource(glm::uvec2(x, y), size);
      if (s.x != x || s.y != y) tile[y * size + x] = tile[s.y * size + s.x];
    }
  }
}
}  // namespace detail

using detail::gMath;

glm::vec3 sphericalFibonacci(std::uint32_t i, std::uint32_t n) {
  return gMath.probeSphericalFibonacci(i, n);
}
glm::vec3 rayDirection(std::uint32_t i, std::uint32_t n, const glm::mat3& rotation) {
  return gMath.probeRayDirection(i, n, rotation);
}

glm::mat3 randomRotation(std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  // 53-bit uniforms in [0,1) computed by hand: std::uniform_real_distribution is not specified
  // bit-exactly across standard libraries, and identical seeds must give identical frames.
  auto uniform = [&rng] { return static_cast<double>(rng() >> 11) * 0x1.0p-53; };
  const double u1 = uniform(), u2 = uniform(), u3 = uniform();
  const double twoPi = 6.283185307179586;
  const double a = std::sqrt(1.0 - u1), b = std::sqrt(u1);
  const glm::quat q(static_cast<float>(b * std::cos(twoPi * u3)),   // w
                    static_cast<float>(a * std::sin(twoPi * u2)),   // x
                    static_cast<float>(a * std::cos(twoPi * u2)),   // y
                    static_cast<float>(b * std::sin(twoPi * u3)));  // z
  return glm::mat3_cast(glm::normalize(q));
}

glm::vec2 octEncode(glm::vec3 d) { return gMath.probeOctEncode(d); }
glm::vec3 octDecode(glm::vec2 p) { return gMath.probeOctDecode(p); }
glm::vec2 texelCentreOct(glm::uvec2 t, std::uint32_t interior) {
  return gMath.probeTexelCentreOct(t, interior);
}
glm::vec3 texelDirection(glm::uvec2 t, std::uint32_t interior) {
  return gMath.probeTexelDirection(t, interior);
}
glm::vec2 tileCoord(glm::vec3 d, std::uint32_t interior) {
  return gMath.probeTileCoord(d, interior);
}
glm::uvec2 borderSource(glm::uvec2 t, std::uint32_t tile) {
  assert(t.x < tile && t.y < tile);
  return gMath.probeBorderSource(t, tile);
}

glm::uvec2 borderCopyCandidate(glm::uvec2 t, std::uint32_t tile, std::uint32_t k) {
  assert(t.x < tile && t.y < tile && k < 8);
  return gMath.probeBorderCopyCandidate(t, tile, k);
}

float irradianceWeight(glm::vec3 t, glm::vec3 r) { return gMath.probeIrradianceWeight(t, r); }
float depthWeight(glm::vec3 t, glm::vec3 r, float s) { return gMath.probeDepthWeight(t, r, s); }
glm::vec3 irradianceFromSums(glm::vec4 s) { return gMath.probeIrradianceFromSums(s); }
glm::vec3 encodeIrradiance(glm::vec3 e, float g) { return gMath.probeEncodeIrradiance(e, g); }
glm::vec3 decodeIrradiance(glm::vec3 s, float g) { return gMath.probeDecodeIrradiance(s, g); }
glm::vec3 hysteresisBlend(glm::vec3 o, glm::vec3 f, float h) {
  return gMath.probeHysteresisBlend3(o, f, h);
}
float adjustHysteresis(glm::vec3 o, glm::vec3 f, float h) {
  return gMath.probeAdjustHysteresis(o, f, h);
}
float rayDepth(float hitT, bool hit, bool backface, float maxDistance, float backfaceScale) {
  return gMath.probeRayDepth(hitT, hit, backface, maxDistance, backfaceScale);
}

float chebyshevWeight(glm::vec2 m, float r, float minVariance) {
  return gMath.probeChebyshevWeight(m, r, minVariance);
}
float backfaceWeight(glm::vec3 d, glm::vec3 n) { return gMath.probeBackfaceWeight(d, n); }
float trilinearWeight(glm::vec3 alpha, std::uint32_t corner) {
  return gMath.probeTrilinearWeight(alpha, corner);
}
glm::vec3 selfShadowBias(glm::vec3 n, glm::vec3 view, float d, float b) {
  return gMath.probeSelfShadowBias(n, view, d, b);
}
float crushWeight(float w, float threshold) { return gMath.probeCrushWeight(w, threshold); }

// ---- ProbeTexels: the CPU reference of the blend pass (one probe), M21 Sec. 2.3.

void ProbeTexels::update(std::span<const glm::vec3> directions, std::span<const glm::vec3> radiance,
                         std::span<const float> depth, float irradianceHysteresis,
                         float depthHysteresis) {
  assert(directions.size() == radiance.size() && directions.size() == depth.size());
  constexpr std::uint32_t kB = gpu_shared::kProbeBorderTexels;
  constexpr std::uint32_t kIrrInterior = gpu_shared::kProbeIrradianceInterior;
  constexpr std::uint32_t kDepthInterior = gpu_shared::kProbeDepthInterior;
  const float gamma = settings_.irradianceGamma;

  for (std::uint32_t y = 0; y < kIrrInterior; ++y) {
    for (std::uint32_t x = 0; x < kIrrInterior; ++x) {
      const glm::vec3 texelDir = gMath.probeTexelDirection(glm::uvec2(x, y), kIrrInterior);
      glm::vec4 sums(0.0f);
      for (std::size_t r = 0; r < directions.size(); ++r) {
        const float w = gMath.probeIrradianceWeight(texelDir, directions[r]);
        sums += glm::vec4(radiance[r] * w, w);
      }
      if (sums.w <= 0.0f) continue;
      glm::vec3& stored = irradiance_[(y + kB) * kIrradianceTile + (x + kB)];
      const glm::vec3 fresh =
          gMath.probeEncodeIrradiance(gMath.probeIrradianceFromSums(sums), gamma);
      const float h = settings_.adaptiveHysteresis
                          ? gMath.probeAdjustHysteresis(stored, fresh, irradianceHysteresis)
                          : irradianceHysteresis;
      stored = gMath.probeHysteresisBlend3(stored, fresh, h);
    }
  }

  for (std::uint32_t y = 0; y < kDepthInterior; ++y) {
    for (std::uint32_t x = 0; x < kDepthInterior; ++x) {
      const glm::vec3 texelDir = gMath.probeTexelDirection(glm::uvec2(x, y), kDepthInterior);
      glm::vec3 sums(0.0f);  // w * d, w * d², w
      for (std::size_t r = 0; r < directions.size(); ++r) {
        const float w = gMath.probeDepthWeight(texelDir, directions[r], settings_.depthSharpness);
        sums += glm::vec3(w * depth[r], w * depth[r] * depth[r], w);
      }
      if (sums.z <= 0.0f) continue;
      glm::vec2& stored = depth_[(y + kB) * kDepthTile + (x + kB)];
      const glm::vec2 fresh(sums.x / sums.z, sums.y / sums.z);
      stored = gMath.probeHysteresisBlend2(stored, fresh, depthHysteresis);
    }
  }
  fillBorders();
}

void ProbeTexels::fillBorders() {
  detail::copyBorders(std::span<glm::vec3>(irradiance_), kIrradianceTile);
  detail::copyBorders(std::span<glm::vec2>(depth_), kDepthTile);
}

glm::vec3 ProbeTexels::irradianceTexel(glm::uvec2 t) const {
  assert(t.x < gpu_shared::kProbeIrradianceInterior && t.y < gpu_shared::kProbeIrradianceInterior);
  constexpr std::uint32_t kB = gpu_shared::kProbeBorderTexels;
  return gMath.probeDecodeIrradiance(irradiance_[(t.y + kB) * kIrradianceTile + (t.x + kB)],
                                     settings_.irradianceGamma);
}

glm::vec3 ProbeTexels::sampleIrradiance(glm::vec3 d) const {
  const glm::vec2 c = gMath.probeTileCoord(d, gpu_shared::kProbeIrradianceInterior);
  return gMath.probeDecodeIrradiance(
      detail::bilinear(std::span<const glm::vec3>(irradiance_), kIrradianceTile, c),
      settings_.irradianceGamma);
}

glm::vec2 ProbeTexels::sampleDepth(glm::vec3 d) const {
  const glm::vec2 c = gMath.probeTileCoord(d, gpu_shared::kProbeDepthInterior);
  return detail::bilinear(std::span<const glm::vec2>(depth_), kDepthTile, c);
}

}  // namespace sdfstream::probe
