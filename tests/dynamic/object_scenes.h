// Random moving-object scenes for the region and traversal tests: a stack description (cascade
// windows only, no bricks) and instances of a box and a sphere mesh with random poses, rotations
// and non-uniform scales -- some spanning many regions, some outside every cascade.
#pragma once

#include <cstdint>
#include <random>

#include <glm/gtc/quaternion.hpp>

#include "objects/instance_set.h"
#include "objects/object_library.h"
#include "streaming/cascade_stack.h"

namespace sdfstream::test {

// Cascade windows centred on the same point (as AnalyticStack), voxel 0.25 m, world origin at
// cascade 0's min corner (10, -4, 20) m: a non-trivial world-to-stack map.
inline CascadeStackImage windowsOnlyStack(int cascades) {
  CascadeStackImage image;
  image.voxelSize0 = 0.25;
  image.cascade0MinWorld = glm::dvec3(10.0, -4.0, 20.0);
  for (int c = 0; c < cascades; ++c) {
    const float scale = float(1 << c);
    gpu_shared::CascadeTraceParams p{};
    p.offsetScale = glm::vec4(glm::vec3(64.0f - 64.0f * scale), scale);
    p.toroidal = glm::uvec4(0u, 0u, 0u, std::uint32_t(c) * gpu_shared::kCascadePageCount);
    image.params.push_back(p);
  }
  return image;
}

struct RandomObjects {
  ObjectLibrary library{ObjectSdfSettings{16, 24, 0.0, 2}};
  InstanceSet instances;
  std::uint32_t box = 0, sphere = 0;

  RandomObjects() {
    box = library.addBox({0.5f, 0.3f, 0.4f}, {0.8f, 0.2f, 0.2f, 1.0f});
    sphere = library.addSphere(0.5f, {0.2f, 0.7f, 0.3f, 1.0f}, 16);
  }

  // `count` instances around the stack's centre (world), within `spread` metres; every 10th is
  // huge (spans many regions), every 17th far outside every cascade.
  void addRandom(const CascadeStackImage& stack, std::uint32_t count, double spread,
                 std::uint64_t seed) {
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    std::uniform_real_distribution<float> s(0.4f, 3.0f);
    const glm::dvec3 centre = stack.cascade0MinWorld + glm::dvec3(64.0 * stack.voxelSize0);
    for (std::uint32_t i = 0; i < count; ++i) {
      ObjectTransform pose;
      pose.translation = centre + spread * glm::dvec3(u(rng), u(rng), u(rng));
      const glm::vec3 axis =
          glm::normalize(glm::vec3(float(u(rng)), float(u(rng)), float(u(rng))) + 1e-3f);
      pose.rotation = glm::angleAxis(float(u(rng)) * 3.14159f, axis);
      pose.scale = glm::vec3(s(rng), s(rng), s(rng));
      if (i % 10 == 3) pose.scale *= 12.0f;
      if (i % 17 == 5) pose.translation += glm::dvec3(5000.0, 0.0, 0.0);
      instances.add(i % 2 ? box : sphere, pose);
    }
  }
};

}  // namespace sdfstream::test
