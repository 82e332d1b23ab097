#include "world/closest_material.h"

#include <cmath>

#include "world/color_pack.h"

namespace sdfstream {

glm::dvec2 closestBarycentrics(glm::dvec3 p, glm::dvec3 a, glm::dvec3 b, glm::dvec3 c) {
  glm::dvec3 ab = b - a, ac = c - a, ap = p - a;
  double d1 = glm::dot(ab, ap), d2 = glm::dot(ac, ap);
  if (d1 <= 0 && d2 <= 0) return {0, 0};
  glm::dvec3 bp = p - b;
  double d3 = glm::dot(ab, bp), d4 = glm::dot(ac, bp);
  if (d3 >= 0 && d4 <= d3) return {1, 0};
  double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) return {d1 / (d1 - d3), 0};
  glm::dvec3 cp = p - c;
  double d5 = glm::dot(ab, cp), d6 = glm::dot(ac, cp);
  if (d6 >= 0 && d5 <= d6) return {0, 1};
  double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) return {0, d2 / (d2 - d6)};
  double va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) {
    double w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
    return {1 - w, w};
  }
  double denom = 1 / (va + vb + vc);
  if (!std::isfinite(denom)) return {0, 0};  // degenerate triangle
  return {vb * denom, vc * denom};
}

PackedMaterial closestMaterial(const TriangleScene& scene, std::uint32_t triangle, glm::dvec3 p,
                               float emissionScale) {
  const glm::uvec3& tri = scene.triangles[triangle];
  const glm::vec2 bary(closestBarycentrics(p, glm::dvec3(scene.positions[tri.x]),
                                           glm::dvec3(scene.positions[tri.y]),
                                           glm::dvec3(scene.positions[tri.z])));
  return {packAlbedo(sampleAlbedo(scene, triangle, bary)),
          packRgb9e5(sampleEmission(scene, triangle, bary) * emissionScale)};
}

}  // namespace sdfstream
