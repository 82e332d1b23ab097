#include <algorithm>
#include <cmath>

#include "world/closest_material.h"
#include "world/level_set_bricks.h"

namespace sdfstream {
namespace {

struct TrianglePoints {
  glm::dvec3 a, b, c;
};

TrianglePoints pointsOf(const TriangleScene& scene, std::size_t t) {
  const glm::uvec3& tri = scene.triangles[t];
  return {glm::dvec3(scene.positions[tri.x]), glm::dvec3(scene.positions[tri.y]),
          glm::dvec3(scene.positions[tri.z])};
}

}  // namespace

std::vector<float> emitterFluxScales(const TriangleScene& scene, const MeshLevelSet& levelSet,
                                     double voxelSize) {
  const std::size_t materialCount = scene.materials.size();
  std::vector<float> scale(materialCount, 1.0f);
  std::vector<double> trueArea(materialCount, 0.0), importedArea(materialCount, 0.0);
  std::vector<std::size_t> crossings(materialCount, 0);
  bool anyEmitter = false;
  for (std::size_t t = 0; t < scene.triangles.size(); ++t) {
    const std::uint32_t m = scene.triangleMaterial[t];
    if (m >= materialCount || scene.materials[m].emissive == glm::vec3(0.0f)) continue;
    const TrianglePoints p = pointsOf(scene, t);
    trueArea[m] += 0.5 * glm::length(glm::cross(p.b - p.a, p.c - p.a));
    anyEmitter = true;
  }
  // A signed level set's surface is the mesh's own: nothing grows.
  if (!anyEmitter || levelSet.isSigned || !levelSet.distance || !levelSet.closest) return scale;

  // The imported surface's area from its crossings of the grid's edges: a plane with unit normal
  // n crosses |n_a| / voxel² edges along axis a per unit area, so each crossing weighted by |n_a|
  // adds voxel² of area (Σ n_a² = 1), exact for a plane at any offset and angle.
  auto distance = levelSet.distance->getConstAccessor();
  auto index = levelSet.closest->getConstAccessor();
  const openvdb::math::Transform& xf = levelSet.distance->transform();
  for (auto it = levelSet.distance->cbeginValueOn(); it; ++it) {
    const openvdb::Coord ijk = it.getCoord();
    const float d0 = *it;
    for (int axis = 0; axis < 3; ++axis) {
      openvdb::Coord next = ijk;
      next[axis] += 1;
      const float d1 = distance.getValue(next);
      if ((d0 < 0.0f) == (d1 < 0.0f)) continue;
      const openvdb::Coord& nearer = std::abs(d0) <= std::abs(d1) ? ijk : next;
      const std::int64_t t = index.getValue(nearer);
      if (t < 0 || std::uint64_t(t) >= scene.triangles.size()) continue;
      const std::uint32_t m = scene.triangleMaterial[std::size_t(t)];
      if (m >= materialCount || trueArea[m] == 0.0) continue;
      const TrianglePoints tri = pointsOf(scene, std::size_t(t));
      const glm::dvec3 facing = glm::cross(tri.b - tri.a, tri.c - tri.a);
      if (!(glm::dot(facing, facing) > 0.0)) continue;
      const double f = double(d0) / (double(d0) - double(d1));
      openvdb::Vec3d at = xf.indexToWorld(openvdb::Vec3d(ijk.x(), ijk.y(), ijk.z()));
      at[axis] += f * voxelSize;
      const glm::dvec3 p(at.x(), at.y(), at.z());
      const glm::dvec3 away = p - closestPointOnTriangle(p, tri.a, tri.b, tri.c);
      // The shell stands half a voxel off the triangle, its normal pointing away from the
      // closest point (round over edges); only the side the triangle faces is seen, the other
      // is the sheet's back or a hollow inside. Beside an edge, in the sheet's plane, is the
      // rim: seen, whichever triangle is closest.
      glm::dvec3 normal = glm::normalize(facing);
      if (glm::dot(away, normal) < -1e-3 * voxelSize) continue;
      const double reach = glm::length(away);
      if (reach > 0.1 * voxelSize) normal = away / reach;
      importedArea[m] += std::abs(normal[axis]) * voxelSize * voxelSize;
      ++crossings[m];
    }
  }
  for (std::size_t m = 0; m < materialCount; ++m) {
    if (trueArea[m] == 0.0 || crossings[m] < 8 || !(importedArea[m] > 0.0)) continue;
    scale[m] = float(std::clamp(trueArea[m] / importedArea[m], 0.5, 2.0));
  }
  return scale;
}

}  // namespace sdfstream
