#include "objects/primitive_meshes.h"

#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>

namespace sdfstream {
namespace {

bool finite(glm::vec4 v) {
  return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z) && std::isfinite(v.w);
}

TriangleScene oneMaterialScene(const char* source, glm::vec4 albedo, glm::vec3 emission) {
  if (!finite(albedo) || !finite(glm::vec4(emission, 0.0f)))
    throw std::invalid_argument(std::string(source) + ": non-finite albedo or emission");
  TriangleScene scene;
  Material material;
  material.baseColorFactor = albedo;
  material.emissive = emission;
  material.name = source;
  scene.materials.push_back(material);
  scene.source = source;
  return scene;
}

void finish(TriangleScene& scene) {
  scene.uvs.assign(scene.positions.size(), glm::vec2(0.0f));
  scene.triangleMaterial.assign(scene.triangles.size(), 0u);
}

}  // namespace

TriangleScene makeBoxMesh(glm::vec3 halfExtents, glm::vec4 linearAlbedo, glm::vec3 emission) {
  if (!finite(glm::vec4(halfExtents, 1.0f)) ||
      !(glm::all(glm::greaterThan(halfExtents, glm::vec3(0.0f)))))
    throw std::invalid_argument("box: half extents must be finite and > 0");
  TriangleScene scene = oneMaterialScene("box", linearAlbedo, emission);
  // Vertex v has x = bit 0, y = bit 1, z = bit 2 set to +halfExtents, else −halfExtents.
  for (int v = 0; v < 8; ++v)
    scene.positions.push_back(halfExtents *
                              glm::vec3(v & 1 ? 1 : -1, v & 2 ? 1 : -1, v & 4 ? 1 : -1));
  // Each face as a quad (a, b, c, d) counter-clockwise seen from outside.
  const std::uint32_t faces[6][4] = {{0, 4, 6, 2}, {1, 3, 7, 5},   // −x, +x
                                     {0, 1, 5, 4}, {2, 6, 7, 3},   // −y, +y
                                     {0, 2, 3, 1}, {4, 5, 7, 6}};  // −z, +z
  for (const auto& f : faces) {
    scene.triangles.push_back({f[0], f[1], f[2]});
    scene.triangles.push_back({f[0], f[2], f[3]});
  }
  finish(scene);
  return scene;
}

TriangleScene makeSphereMesh(float radius, glm::vec4 linearAlbedo, std::uint32_t segments) {
  if (!std::isfinite(radius) || !(radius > 0.0f))
    throw std::invalid_argument("sphere: radius must be finite and > 0");
  if (segments < 3 || segments > 4096)
    throw std::invalid_argument("sphere: segments " + std::to_string(segments) +
                                " outside 3..4096");
  TriangleScene scene = oneMaterialScene("sphere", linearAlbedo, glm::vec3(0.0f));
  const std::uint32_t rings = sphereRings(segments);
  const double pi = std::numbers::pi;
  scene.positions.push_back({0.0f, radius, 0.0f});  // north pole, vertex 0
  for (std::uint32_t r = 1; r < rings; ++r) {
    const double polar = pi * r / rings;
    for (std::uint32_t s = 0; s < segments; ++s) {
      const double azimuth = 2.0 * pi * s / segments;
      scene.positions.push_back(glm::vec3(
          double(radius) * glm::dvec3(std::sin(polar) * std::cos(azimuth), std::cos(polar),
                                      -std::sin(polar) * std::sin(azimuth))));
    }
  }
  const std::uint32_t south = std::uint32_t(scene.positions.size());
  scene.positions.push_back({0.0f, -radius, 0.0f});
  auto ring = [&](std::uint32_t r, std::uint32_t s) {
    return 1 + (r - 1) * segments + s % segments;
  };
  for (std::uint32_t s = 0; s < segments; ++s) {
    scene.triangles.push_back({0, ring(1, s), ring(1, s + 1)});
    for (std::uint32_t r = 1; r + 1 < rings; ++r) {
      scene.triangles.push_back({ring(r, s), ring(r + 1, s), ring(r + 1, s + 1)});
      scene.triangles.push_back({ring(r, s), ring(r + 1, s + 1), ring(r, s + 1)});
    }
    scene.triangles.push_back({ring(rings - 1, s), south, ring(rings - 1, s + 1)});
  }
  finish(scene);
  return scene;
}

}  // namespace sdfstream
