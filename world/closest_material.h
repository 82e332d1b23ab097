// The material of a mesh at the point of one triangle closest to a query point, packed as the
// brick atlases store it. One rule for static bricks (meshToWorld) and object SDFs (objects/), so
// a mesh looks the same whichever way it is imported.
#pragma once

#include <cstdint>

#include <glm/glm.hpp>

#include "world/triangle_scene.h"

namespace sdfstream {

struct PackedMaterial {
  std::uint32_t albedo = 0;    // RGBA8, sRGB-encoded RGB (color_pack.h packAlbedo)
  std::uint32_t emission = 0;  // RGB9E5, linear (color_pack.h packRgb9e5)
};

// Closest point on triangle (a,b,c) to p as barycentrics (b1, b2) of b and c (Ericson, Real-Time
// Collision Detection 5.1.5). Degenerate triangles answer (0,0). Also declared, for world/'s
// OpenVDB-side code, in level_set_bricks.h.
glm::dvec2 closestBarycentrics(glm::dvec3 p, glm::dvec3 a, glm::dvec3 b, glm::dvec3 c);
// The point of triangle (a,b,c) closest to p (closestBarycentrics, as a point).
inline glm::dvec3 closestPointOnTriangle(glm::dvec3 p, glm::dvec3 a, glm::dvec3 b, glm::dvec3 c) {
  const glm::dvec2 bary = closestBarycentrics(p, a, b, c);
  return a + (b - a) * bary.x + (c - a) * bary.y;
}

// sampleAlbedo / sampleEmission at the point of `triangle` closest to p (same space as
// scene.positions). Preconditions: triangle < scene.triangles.size(), its vertex and material
// indices valid (validateScene plus a material check); asserted by sampleAlbedo in debug.
// emissionScale multiplies the emission (the static importers' emitterFluxScales).
PackedMaterial closestMaterial(const TriangleScene& scene, std::uint32_t triangle, glm::dvec3 p,
                               float emissionScale = 1.0f);

}  // namespace sdfstream
