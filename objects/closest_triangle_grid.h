// Exact-in-practice closest triangles on a dense grid, grown from seeds near the surface.
// OpenVDB's meshToVolume gives each voxel of its narrow band the closest polygon it found, but a
// band wide enough to cover a whole object box costs seconds (its band expansion dominates), and
// its answer near edges and corners is sometimes not the closest polygon: on a box 64 voxels
// across, distances came out up to 0.8 voxel too large -- enough for a sphere tracer to step
// through a corner. So the SDF takes a narrow band from OpenVDB and this pass spreads and
// repairs it. Internal to objects/.
#pragma once

#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "world/triangle_scene.h"

namespace sdfstream {

inline constexpr std::uint32_t kNoTriangle = UINT32_MAX;

struct GridFrame {
  glm::uvec3 dims{0};    // samples per axis, x fastest
  glm::dvec3 origin{0};  // position of sample (0,0,0), mesh space
  double spacing = 0;    // sample spacing, mesh units
};

// Unsigned distance (mesh units) from p to triangle t.
double triangleDistance(const TriangleScene& mesh, std::uint32_t t, glm::dvec3 p);

// On entry triangle[i] is a guess for sample i or kNoTriangle; at least one sample has a guess.
// On return every sample holds the closest triangle among those of its 3×3×3 neighbourhood,
// iterated to a fixed point (a sample changes only to a strictly closer triangle, or an equally
// close one of lower index), and distance[i] its exact unsigned distance to it (mesh units).
// That is the closest triangle of the whole mesh wherever the closest-triangle regions are not
// thinner than a sample spacing; tests compare against brute force. Jacobi updates over a
// sorted work list, so the result does not depend on thread scheduling. Cost: about 27 triangle
// distances per sample per visit; samples are revisited only next to a change.
void growClosestTriangles(const TriangleScene& mesh, const GridFrame& grid,
                          std::vector<std::uint32_t>& triangle, std::vector<double>& distance);

}  // namespace sdfstream
