// Small closed and open meshes built in code, and brute-force distance / inside tests on them:
// the reference for the mesh → SDF tests.
#pragma once

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <utility>

#include <glm/glm.hpp>

#include "world/triangle_scene.h"

namespace sdfstream::test {

inline TriangleScene withDefaultMaterial(TriangleScene s, glm::vec4 albedo = glm::vec4(0.8f),
                                         glm::vec3 emissive = glm::vec3(0.0f)) {
  s.uvs.assign(s.positions.size(), glm::vec2(0.0f));
  s.triangleMaterial.assign(s.triangles.size(), 0);
  Material m;
  m.baseColorFactor = albedo;
  m.emissive = emissive;
  m.name = "test";
  s.materials = {m};
  return s;
}

// Icosphere with shared vertices (closed), counter-clockwise seen from outside.
inline TriangleScene icosphere(glm::vec3 centre, float radius, int subdivisions) {
  const float t = (1.0f + std::sqrt(5.0f)) / 2.0f;
  std::vector<glm::vec3> v = {{-1, t, 0}, {1, t, 0}, {-1, -t, 0}, {1, -t, 0},
                              {0, -1, t}, {0, 1, t}, {0, -1, -t}, {0, 1, -t},
                              {t, 0, -1}, {t, 0, 1}, {-t, 0, -1}, {-t, 0, 1}};
  for (auto& p : v) p = glm::normalize(p);
  std::vector<glm::uvec3> f = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11},
                               {1, 5, 9},  {5, 11, 4}, {11, 10, 2}, {10, 7, 6}, {7, 1, 8},
                               {3, 9, 4},  {3, 4, 2},  {3, 2, 6},   {3, 6, 8},  {3, 8, 9},
                               {4, 9, 5},  {2, 4, 11}, {6, 2, 10},  {8, 6, 7},  {9, 8, 1}};
  for (int s = 0; s < subdivisions; ++s) {
    std::map<std::pair<unsigned, unsigned>, unsigned> mid;
    auto midpoint = [&](unsigned a, unsigned b) {
      auto key = std::minmax(a, b);
      auto it = mid.find(key);
      if (it != mid.end()) return it->second;
      v.push_back(glm::normalize(v[a] + v[b]));
      return mid[key] = unsigned(v.size() - 1);
    };
    std::vector<glm::uvec3> next;
    for (auto tri : f) {
      unsigned a = midpoint(tri.x, tri.y), b = midpoint(tri.y, tri.z), c = midpoint(tri.z, tri.x);
      next.insert(next.end(), {{tri.x, a, c}, {tri.y, b, a}, {tri.z, c, b}, {a, b, c}});
    }
    f = std::move(next);
  }
  TriangleScene scene;
  for (auto& p : v) scene.positions.push_back(centre + radius * p);
  scene.triangles = f;
  scene.source = "icosphere";
  return withDefaultMaterial(std::move(scene));
}

// A closed box with separate (unshared) vertices per face, rotated so no face is axis-aligned.
inline TriangleScene rotatedBox(glm::vec3 centre, glm::vec3 half, glm::mat3 rotation) {
  TriangleScene scene;
  for (int axis = 0; axis < 3; ++axis)
    for (int side = -1; side <= 1; side += 2) {
      glm::vec3 n(0), u(0), w(0);
      n[axis] = float(side);
      u[(axis + 1) % 3] = 1;
      w[(axis + 2) % 3] = 1;
      if (side < 0) std::swap(u, w);  // keep counter-clockwise from outside
      unsigned base = unsigned(scene.positions.size());
      for (int k = 0; k < 4; ++k) {
        glm::vec3 p = n + u * ((k & 1) ? 1.0f : -1.0f) + w * ((k & 2) ? 1.0f : -1.0f);
        scene.positions.push_back(centre + rotation * (p * half));
      }
      scene.triangles.push_back({base, base + 1, base + 3});
      scene.triangles.push_back({base, base + 3, base + 2});
    }
  scene.source = "box";
  return withDefaultMaterial(std::move(scene));
}

// Axis-aligned square sheet at height z (two triangles, open).
inline TriangleScene quadSheet(float halfSize, float z) {
  TriangleScene scene;
  scene.positions = {{-halfSize, -halfSize, z},
                     {halfSize, -halfSize, z},
                     {halfSize, halfSize, z},
                     {-halfSize, halfSize, z}};
  scene.triangles = {{0, 1, 2}, {0, 2, 3}};
  scene.source = "quad";
  return withDefaultMaterial(std::move(scene));
}

// An open floor sheet (so the whole scene imports as shells) and above it a closed panel box,
// 2.4 x 0.1 x 1 m, of an emitting material (material 1). Unturned, the panel's faces lie on the
// grid planes of 5 and 10 cm voxels.
inline constexpr glm::vec3 kEmittingPanelHalf(1.2f, 0.05f, 0.5f);
inline constexpr glm::vec3 kEmittingPanelEmission(4.0f, 3.0f, 2.0f);
inline TriangleScene floorAndEmittingPanel(glm::mat3 rotation = glm::mat3(1.0f)) {
  TriangleScene scene = quadSheet(3.0f, 0.0f);
  TriangleScene panel = rotatedBox({0.0f, 0.05f, 2.5f}, kEmittingPanelHalf, rotation);
  const auto base = std::uint32_t(scene.positions.size());
  scene.positions.insert(scene.positions.end(), panel.positions.begin(), panel.positions.end());
  for (const glm::uvec3& t : panel.triangles) {
    scene.triangles.push_back(t + base);
    scene.triangleMaterial.push_back(1);
  }
  scene.uvs.assign(scene.positions.size(), glm::vec2(0.0f));
  Material light;
  light.name = "light";
  light.emissive = kEmittingPanelEmission;
  scene.materials.push_back(light);
  return scene;
}
// The panel's area grown by r on every side as a box (sharp edges).
inline double emittingPanelArea(double r) {
  const glm::dvec3 e = 2.0 * glm::dvec3(kEmittingPanelHalf) + 2.0 * r;
  return 2.0 * (e.x * e.y + e.y * e.z + e.x * e.z);
}

inline double pointTriangleDistance(glm::dvec3 p, glm::dvec3 a, glm::dvec3 b, glm::dvec3 c) {
  // Ericson 5.1.5, written independently of the importer's copy.
  glm::dvec3 ab = b - a, ac = c - a, ap = p - a;
  double d1 = dot(ab, ap), d2 = dot(ac, ap);
  if (d1 <= 0 && d2 <= 0) return length(p - a);
  glm::dvec3 bp = p - b;
  double d3 = dot(ab, bp), d4 = dot(ac, bp);
  if (d3 >= 0 && d4 <= d3) return length(p - b);
  double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) return length(p - (a + ab * (d1 / (d1 - d3))));
  glm::dvec3 cp = p - c;
  double d5 = dot(ab, cp), d6 = dot(ac, cp);
  if (d6 >= 0 && d5 <= d6) return length(p - c);
  double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) return length(p - (a + ac * (d2 / (d2 - d6))));
  double va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0)
    return length(p - (b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)))));
  double denom = 1 / (va + vb + vc);
  return length(p - (a + ab * (vb * denom) + ac * (vc * denom)));
}

// Unsigned distance to the nearest triangle.
inline double bruteForceDistance(const TriangleScene& s, glm::dvec3 p) {
  double best = std::numeric_limits<double>::infinity();
  for (auto t : s.triangles)
    best = std::min(best,
                    pointTriangleDistance(p, s.positions[t.x], s.positions[t.y], s.positions[t.z]));
  return best;
}

// Generalised winding number (solid angles, Van Oosterom & Strackee): ~1 inside, ~0 outside.
inline double windingNumber(const TriangleScene& s, glm::dvec3 p) {
  double sum = 0;
  for (auto t : s.triangles) {
    glm::dvec3 a = glm::dvec3(s.positions[t.x]) - p, b = glm::dvec3(s.positions[t.y]) - p,
               c = glm::dvec3(s.positions[t.z]) - p;
    double la = length(a), lb = length(b), lc = length(c);
    double num = dot(a, cross(b, c));
    double den = la * lb * lc + dot(a, b) * lc + dot(b, c) * la + dot(c, a) * lb;
    sum += 2 * std::atan2(num, den);
  }
  return sum / (4 * M_PI);
}

}  // namespace sdfstream::test
