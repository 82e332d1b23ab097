// Normals of an imported open mesh: a box turned about the vertical axis, open at the bottom and
// standing on a floor (the Cornell box's blocks). Open meshes become shells |d| - 0.5 voxel
// (world/mesh_to_sdf.h); their normals must be the faces' normals, not striped by the grid.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

#include <glm/gtc/matrix_transform.hpp>

#include "gi/cpu_tracer.h"
#include "streaming/cascade.h"
#include "tests/world/mesh_fixtures.h"
#include "world/mesh_to_sdf.h"

namespace sdfstream {
namespace {

constexpr double kVoxel = 0.02;  // metres
constexpr float kTurn = 17.0f;   // degrees about +y

struct NormalError {
  double mean = 0.0;
  double max = 0.0;
  int hits = 0;
};

// A box 0.6 x 0.9 x 0.5 m turned by kTurn, without its bottom face, on a 2 m floor at y = 0.
TriangleScene openBoxOnFloor() {
  const glm::mat3 turn(glm::rotate(glm::mat4(1.0f), glm::radians(kTurn), glm::vec3(0, 1, 0)));
  TriangleScene scene =
      test::rotatedBox(glm::vec3(0.0f, 0.45f, 0.0f), glm::vec3(0.3f, 0.45f, 0.25f), turn);
  scene.triangles.erase(scene.triangles.begin() + 4, scene.triangles.begin() + 6);  // -y face
  const unsigned base = unsigned(scene.positions.size());
  for (glm::vec2 c : {glm::vec2(-1, -1), glm::vec2(1, -1), glm::vec2(1, 1), glm::vec2(-1, 1)})
    scene.positions.push_back(glm::vec3(c.x, 0.0f, c.y));
  scene.triangles.push_back({base, base + 2, base + 1});
  scene.triangles.push_back({base, base + 3, base + 2});
  return test::withDefaultMaterial(std::move(scene));
}

// Angle (degrees) between the traced normal and `normal` over a grid of rays that hit the plane
// through `centre` spanned by u and v head-on, within the given half extents.
NormalError normalErrorOver(const CascadeImage& cascade, glm::dvec3 centre, glm::dvec3 normal,
                            glm::dvec3 u, double halfU, glm::dvec3 v, double halfV) {
  std::vector<gpu_shared::TraceRay> rays;
  for (int i = 0; i <= 40; ++i)
    for (int j = 0; j <= 40; ++j) {
      glm::dvec3 target = centre + u * (halfU * (i / 20.0 - 1.0)) + v * (halfV * (j / 20.0 - 1.0));
      gpu_shared::TraceRay ray;
      ray.originTMin = glm::vec4(cascade.toCascade(target + normal * 0.3), 0.0f);
      ray.dirTMax = glm::vec4(glm::vec3(-normal), 1e30f);
      rays.push_back(ray);
    }
  NormalError e;
  for (const gpu_shared::TraceHit& hit : traceRaysCpu(cascade, rays, TraceSettings{})) {
    if ((hit.flags & gpu_shared::kHitFlagHit) == 0u) continue;
    const double c = std::clamp(glm::dot(glm::dvec3(glm::vec3(hit.normalT)), normal), -1.0, 1.0);
    const double degrees = std::acos(c) * 180.0 / 3.141592653589793;
    e.mean += degrees;
    e.max = std::max(e.max, degrees);
    ++e.hits;
  }
  if (e.hits > 0) e.mean /= e.hits;
  return e;
}

TEST(SdfNormal, TurnedOpenBoxShowsFlatFacesAndFloor) {
  const TriangleScene scene = openBoxOnFloor();
  ASSERT_FALSE(isClosedMesh(scene));
  const World world = meshToWorld(scene, kVoxel, ImportLimits{});
  const CascadeImage cascade = buildCascade(world, cascadeOriginForWorld(world));

  const double a = glm::radians(double(kTurn));
  const glm::dvec3 front(std::sin(a), 0.0, std::cos(a));  // the turned +z face's normal
  const glm::dvec3 side(std::cos(a), 0.0, -std::sin(a));  // the turned +x face's normal
  const glm::dvec3 up(0.0, 1.0, 0.0);
  // Faces away from their edges by 4 voxels; the floor 4 voxels beyond the box's corners.
  const double margin = 4 * kVoxel;
  const NormalError frontFace = normalErrorOver(cascade, front * 0.25 + up * 0.45, front, side,
                                                0.3 - margin, up, 0.45 - margin);
  const NormalError sideFace = normalErrorOver(cascade, side * 0.3 + up * 0.45, side, front,
                                               0.25 - margin, up, 0.45 - margin);
  const double reach = std::hypot(0.3, 0.25) + margin;
  const NormalError floor = normalErrorOver(cascade, glm::dvec3(reach + 0.2, 0.0, 0.0), up,
                                            glm::dvec3(1, 0, 0), 0.2, glm::dvec3(0, 0, 1), 0.6);
  // The floor 1-4 voxels in front of the face: the concave corner, where a normal taken farther
  // out would point along the face's (near normals there: mean 2.4, max 27 degrees).
  const NormalError corner = normalErrorOver(cascade, front * (0.25 + 2.5 * kVoxel), up, side,
                                             0.3 - margin, front, 1.5 * kVoxel);
  std::printf(
      "[figures] normals of a box turned %.0f degrees (voxel %.2f m), degrees off the "
      "face: front mean %.3f max %.3f (%d hits), side mean %.3f max %.3f (%d), floor "
      "mean %.3f max %.3f (%d), floor at the face mean %.3f max %.3f (%d)\n",
      kTurn, kVoxel, frontFace.mean, frontFace.max, frontFace.hits, sideFace.mean, sideFace.max,
      sideFace.hits, floor.mean, floor.max, floor.hits, corner.mean, corner.max, corner.hits);
  for (const NormalError& e : {frontFace, sideFace, floor}) {
    EXPECT_GT(e.hits, 1600);
    // Central differences next to the shell tilt these by 6-9 degrees on average, up to ~15.
    EXPECT_LT(e.mean, 0.5);
    EXPECT_LT(e.max, 2.0);
  }
  EXPECT_GT(corner.hits, 1600);
  EXPECT_LT(corner.mean, 4.5);
  EXPECT_LT(corner.max, 35.0);
}

}  // namespace
}  // namespace sdfstream
