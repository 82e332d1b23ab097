// Random numbers and hemisphere sampling for the reference path tracer (reference/path_tracer.h).
//
// Determinism (deterministic seeds): there is no shared generator. Every (seed, point,
// sample) triple keys its own small PCG32 stream, so a point's estimate depends only on those
// numbers and never on which thread ran it or in which order — the result is bit-identical for
// any thread count.
#pragma once

#include <cmath>
#include <cstdint>

#include <glm/glm.hpp>

namespace sdfstream::reference {

// SplitMix64 finaliser (Steele et al. 2014): a bijective 64-bit mix, used to turn structured keys
// (seed, point, sample) into well-spread generator states.
inline std::uint64_t mix64(std::uint64_t x) {
  x += 0x9e3779b97f4a7c15ull;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ull;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebull;
  return x ^ (x >> 31);
}

// PCG32 (O'Neill 2014, XSH-RR output), one stream per (seed, point, sample).
class SampleRng {
 public:
  SampleRng(std::uint64_t seed, std::uint64_t point, std::uint64_t sample) {
    state_ = mix64(seed ^ mix64(point ^ mix64(sample)));
    increment_ = (mix64(state_ ^ 0x632be59bd9b4e019ull) << 1u) | 1u;  // odd: full period
    next();
  }

  std::uint32_t next() {
    const std::uint64_t old = state_;
    state_ = old * 6364136223846793005ull + increment_;
    const auto xorshifted = std::uint32_t(((old >> 18u) ^ old) >> 27u);
    const auto rot = std::uint32_t(old >> 59u);
    return (xorshifted >> rot) | (xorshifted << ((32u - rot) & 31u));
  }

  // Uniform in [0, 1): 24 random bits, so the value is exact in float and never rounds up to 1.
  float uniform() { return float(next() >> 8u) * (1.0f / 16777216.0f); }

 private:
  std::uint64_t state_;
  std::uint64_t increment_;
};

// Orthonormal basis around a unit normal (Duff et al. 2017, "Building an Orthonormal Basis,
// Revisited"): no branch on the normal's direction, no precision loss near the poles.
inline void orthonormalBasis(const glm::vec3& n, glm::vec3& t, glm::vec3& b) {
  const float sign = std::copysign(1.0f, n.z);
  const float a = -1.0f / (sign + n.z);
  const float c = n.x * n.y * a;
  t = glm::vec3(1.0f + sign * n.x * n.x * a, sign * c, -sign * n.x);
  b = glm::vec3(c, sign + n.y * n.y * a, -n.y);
}

// Cosine-weighted direction in the hemisphere around unit n (pdf = cos θ / π), by Malley's method:
// a uniform point on the unit disk lifted onto the hemisphere.
inline glm::vec3 cosineHemisphere(const glm::vec3& n, float u1, float u2) {
  const float r = std::sqrt(u1);
  const float phi = 6.28318530717958647692f * u2;
  const float x = r * std::cos(phi), y = r * std::sin(phi);
  const float z = std::sqrt(std::max(0.0f, 1.0f - u1));
  glm::vec3 t, b;
  orthonormalBasis(n, t, b);
  return glm::normalize(x * t + y * b + z * n);
}

}  // namespace sdfstream::reference
