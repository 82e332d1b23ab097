// Built-in closed meshes for tests, the demo and the stress benchmark: the same triangles the
// object library turns into SDFs, so tests can path-trace or brute-force them as a reference.
#pragma once

#include <cstdint>

#include <glm/glm.hpp>

#include "world/triangle_scene.h"

namespace sdfstream {

// Axis-aligned box centred on the origin: 8 shared vertices, 12 counter-clockwise (outward)
// triangles, one material. source = "box". halfExtents must be finite and > 0, albedo and
// emission finite (std::invalid_argument otherwise).
TriangleScene makeBoxMesh(glm::vec3 halfExtents, glm::vec4 linearAlbedo,
                          glm::vec3 emission = glm::vec3(0.0f));

// UV sphere centred on the origin with all vertices on the sphere (so the faces lie inside it by
// at most radius·(1 − cos(π/segments)·cos(π/(2·rings)))): `segments` around the y axis,
// rings = max(2, segments / 2) bands from pole to pole, poles shared, counter-clockwise outward.
// source = "sphere". radius finite > 0, 3 <= segments <= 4096 (std::invalid_argument otherwise).
TriangleScene makeSphereMesh(float radius, glm::vec4 linearAlbedo, std::uint32_t segments = 24);

// Bands from pole to pole of makeSphereMesh(…, segments).
inline std::uint32_t sphereRings(std::uint32_t segments) {
  return segments / 2 > 2 ? segments / 2 : 2;
}

}  // namespace sdfstream
