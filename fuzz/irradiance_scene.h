// The fixed query the irradiance-cache fuzzer reads its files for, shared with make_seeds.cpp
// so a seed carries the very key the fuzzer asks for. Small on purpose: an invalid file makes
// cachedIrradiance trace the query again, once per fuzz input.
#pragma once

#include <memory>
#include <vector>

#include <glm/glm.hpp>

#include "reference/irradiance_cache.h"
#include "reference/path_tracer.h"
#include "world/scene_lights.h"
#include "world/triangle_scene.h"

namespace sdfstream::fuzz {

struct IrradianceQuery {
  TriangleScene scene;  // a grey floor under a small emissive quad
  SceneLights lights;   // one point light
  std::vector<glm::vec3> positions{{0.0f, 0.0f, 0.0f}, {0.5f, 0.0f, -0.5f}};
  std::vector<glm::vec3> normals{{0.0f, 1.0f, 0.0f}, {0.0f, 1.0f, 0.0f}};
  static constexpr std::uint32_t kSamples = 2;
  static constexpr reference::IrradianceKind kKind = reference::IrradianceKind::Total;
  std::unique_ptr<reference::PathTracer> tracer;  // reads `scene`: declared after it

  IrradianceQuery() {
    auto quad = [&](float y, float half, std::uint32_t material) {
      const auto base = std::uint32_t(scene.positions.size());
      for (glm::vec3 p : {glm::vec3(-half, y, -half), glm::vec3(half, y, -half),
                          glm::vec3(half, y, half), glm::vec3(-half, y, half)}) {
        scene.positions.push_back(p);
        scene.uvs.push_back(glm::vec2(0.0f));
      }
      scene.triangles.push_back({base, base + 1, base + 2});
      scene.triangles.push_back({base, base + 2, base + 3});
      scene.triangleMaterial.insert(scene.triangleMaterial.end(), 2, material);
    };
    Material grey, lamp;
    grey.baseColorFactor = glm::vec4(0.6f, 0.6f, 0.6f, 1.0f);
    lamp.baseColorFactor = glm::vec4(0.2f, 0.2f, 0.2f, 1.0f);
    lamp.emissive = glm::vec3(2.0f);
    scene.materials = {grey, lamp};
    quad(0.0f, 2.0f, 0);
    quad(1.5f, 0.5f, 1);
    SceneLight point;
    point.type = SceneLight::Type::Point;
    point.position = {0.0, 1.0, 0.5};
    point.intensity = 1.0f;
    lights.lights.push_back(point);
    reference::PathTracerSettings settings;
    settings.maxDepth = 2;
    tracer = std::make_unique<reference::PathTracer>(scene, lights, settings);
  }
};

}  // namespace sdfstream::fuzz
