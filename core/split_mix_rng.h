// A tiny deterministic random source for scripted placement and motion: the same numbers on
// every platform and compiler (std:: distributions are not), so a seed always gives the same
// scene. Used by objects/scripted_motion.cpp, demo/moving_objects.cpp and world/generate_world.cpp.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numbers>

#include <glm/glm.hpp>
#include <glm/gtc/quaternion.hpp>

namespace sdfstream {

// SplitMix64.
struct SplitMixRng {
  std::uint64_t state;
  std::uint64_t next() {
    std::uint64_t z = (state += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
  }
  double uniform() { return double(next() >> 11) * 0x1.0p-53; }  // [0, 1)
  double uniform(double lo, double hi) { return lo + (hi - lo) * uniform(); }
  // Uniform rotation (Shoemake, Graphics Gems III).
  glm::quat rotation() {
    const double u1 = uniform(), u2 = 2 * std::numbers::pi * uniform(),
                 u3 = 2 * std::numbers::pi * uniform();
    const double a = std::sqrt(1 - u1), b = std::sqrt(u1);
    return glm::quat(float(b * std::cos(u3)), float(a * std::sin(u2)), float(a * std::cos(u2)),
                     float(b * std::sin(u3)));
  }
  glm::dvec3 direction() {
    const double z = uniform(-1, 1), phi = 2 * std::numbers::pi * uniform();
    const double r = std::sqrt(std::max(0.0, 1 - z * z));
    return {r * std::cos(phi), r * std::sin(phi), z};
  }
};

}  // namespace sdfstream
