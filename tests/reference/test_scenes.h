// Scenes built in code for the path tracer's analytic tests: a closed box (white furnace) and
// open quads (direct light), each with one material per quad.
#pragma once

#include <cmath>
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "world/triangle_scene.h"

namespace sdfstream::test {

// Adds a material and returns its index.
inline std::uint32_t addMaterial(TriangleScene& s, glm::vec3 albedo, glm::vec3 emission = {}) {
  Material m;
  m.baseColorFactor = glm::vec4(albedo, 1.0f);
  m.emissive = emission;
  s.materials.push_back(m);
  return std::uint32_t(s.materials.size() - 1);
}

// The quad a, b, c, d (in order around its edge) as two triangles of `material`.
inline void addQuad(TriangleScene& s, glm::vec3 a, glm::vec3 b, glm::vec3 c, glm::vec3 d,
                    std::uint32_t material) {
  const auto base = std::uint32_t(s.positions.size());
  for (const glm::vec3& p : {a, b, c, d}) {
    s.positions.push_back(p);
    s.uvs.push_back(glm::vec2(0.0f));
  }
  s.triangles.push_back({base, base + 1, base + 2});
  s.triangles.push_back({base, base + 2, base + 3});
  s.triangleMaterial.push_back(material);
  s.triangleMaterial.push_back(material);
}

// Square of half-size `half` in the plane y = height.
inline void addFloor(TriangleScene& s, float half, float height, std::uint32_t material) {
  addQuad(s, {-half, height, -half}, {half, height, -half}, {half, height, half},
          {-half, height, half}, material);
}

// A closed axis-aligned box [lo, hi]: 12 triangles sharing its 8 corners (watertight), all of
// one material. Winding is irrelevant: the tracer treats surfaces as two-sided.
inline TriangleScene closedBox(glm::vec3 lo, glm::vec3 hi, glm::vec3 albedo, glm::vec3 emission) {
  TriangleScene s;
  const std::uint32_t m = addMaterial(s, albedo, emission);
  for (int i = 0; i < 8; ++i) {
    s.positions.push_back({i & 1 ? hi.x : lo.x, i & 2 ? hi.y : lo.y, i & 4 ? hi.z : lo.z});
    s.uvs.push_back(glm::vec2(0.0f));
  }
  const std::uint32_t faces[6][4] = {{0, 2, 6, 4}, {1, 5, 7, 3}, {0, 4, 5, 1},
                                     {2, 3, 7, 6}, {0, 1, 3, 2}, {4, 6, 7, 5}};
  for (const auto& f : faces) {
    s.triangles.push_back({f[0], f[1], f[2]});
    s.triangles.push_back({f[0], f[2], f[3]});
    s.triangleMaterial.push_back(m);
    s.triangleMaterial.push_back(m);
  }
  return s;
}

// Points on the six inner walls of the box [lo, hi] with inward normals, spread
// by a fixed low-discrepancy pattern (same points every run), kept 5% away from the edges.
struct SurfacePoints {
  std::vector<glm::vec3> positions;
  std::vector<glm::vec3> normals;
};

inline SurfacePoints boxWallPoints(glm::vec3 lo, glm::vec3 hi, int count) {
  SurfacePoints p;
  for (int i = 0; i < count; ++i) {
    const int axis = i % 3;
    const bool upper = (i / 3) % 2 == 1;
    // R2 sequence (Roberts 2018) for the two in-plane coordinates.
    const float u = 0.05f + 0.9f * std::fmod(0.5f + 0.7548776662f * float(i), 1.0f);
    const float v = 0.05f + 0.9f * std::fmod(0.5f + 0.5698402910f * float(i), 1.0f);
    glm::vec3 t(0.0f), n(0.0f);
    t[axis] = upper ? 1.0f : 0.0f;
    t[(axis + 1) % 3] = u;
    t[(axis + 2) % 3] = v;
    n[axis] = upper ? -1.0f : 1.0f;
    p.positions.push_back(lo + t * (hi - lo));
    p.normals.push_back(n);
  }
  return p;
}

}  // namespace sdfstream::test
