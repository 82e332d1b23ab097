// Exact ray casting on the source triangles with Embree: the independent reference that the
// SDF traversal is checked against, and the path tracer's intersector (reference/path_tracer.h).
#pragma once

#include <optional>

#include <glm/glm.hpp>

#include "world/triangle_scene.h"

struct RTCDeviceTy;
struct RTCSceneTy;

namespace sdfstream {

class EmbreeScene {
 public:
  // Copies the scene's positions and triangles into Embree. Thread-safe to query afterwards.
  explicit EmbreeScene(const TriangleScene& scene);
  ~EmbreeScene();
  EmbreeScene(const EmbreeScene&) = delete;
  EmbreeScene& operator=(const EmbreeScene&) = delete;

  struct Hit {
    float t;            // distance along the (unit) direction, world units
    glm::vec3 normal;   // unit geometric normal (unoriented)
    unsigned triangle;  // index into TriangleScene::triangles
    glm::vec2 bary;     // barycentrics (b1, b2) of vertices 1 and 2, as sampleAlbedo takes them
  };
  // Closest hit within (tMin, tMax), or nullopt.
  std::optional<Hit> intersect(const glm::vec3& origin, const glm::vec3& dir, float tMin,
                               float tMax) const;
  // Whether anything is hit within (tMin, tMax): the shadow-ray query (any hit, no sorting, so
  // cheaper than intersect()).
  bool occluded(const glm::vec3& origin, const glm::vec3& dir, float tMin, float tMax) const;

 private:
  RTCDeviceTy* device_ = nullptr;
  RTCSceneTy* scene_ = nullptr;
};

}  // namespace sdfstream
