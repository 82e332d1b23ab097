#include "objects/closest_triangle_grid.h"

#include <algorithm>
#include <cassert>
#include <limits>
#include <numeric>

#include <tbb/parallel_for.h>

#include "world/closest_material.h"

namespace sdfstream {

double triangleDistance(const TriangleScene& mesh, std::uint32_t t, glm::dvec3 p) {
  const glm::uvec3& tri = mesh.triangles[t];
  const glm::dvec3 a(mesh.positions[tri.x]), b(mesh.positions[tri.y]), c(mesh.positions[tri.z]);
  return glm::length(closestPointOnTriangle(p, a, b, c) - p);
}

void growClosestTriangles(const TriangleScene& mesh, const GridFrame& grid,
                          std::vector<std::uint32_t>& triangle, std::vector<double>& distance) {
  const glm::ivec3 dims(grid.dims);
  const std::size_t count = triangle.size();
  assert(count == std::size_t(grid.dims.x) * grid.dims.y * grid.dims.z);
  const double kInf = std::numeric_limits<double>::infinity();
  auto coord = [&](std::size_t i) {
    return glm::ivec3(int(i % dims.x), int(i / dims.x % dims.y),
                      int(i / (std::size_t(dims.x) * dims.y)));
  };
  // Calls f(neighbour index) for the in-grid samples of the 3×3×3 block around c (c included).
  auto forNeighbours = [&](glm::ivec3 c, auto&& f) {
    for (int z = std::max(c.z - 1, 0); z <= std::min(c.z + 1, dims.z - 1); ++z)
      for (int y = std::max(c.y - 1, 0); y <= std::min(c.y + 1, dims.y - 1); ++y)
        for (int x = std::max(c.x - 1, 0); x <= std::min(c.x + 1, dims.x - 1); ++x)
          f(x + std::size_t(dims.x) * (y + std::size_t(dims.y) * z));
  };
  auto position = [&](glm::ivec3 c) { return grid.origin + grid.spacing * glm::dvec3(c); };

  distance.assign(count, kInf);
  tbb::parallel_for(std::size_t(0), count, [&](std::size_t i) {
    if (triangle[i] != kNoTriangle)
      distance[i] = triangleDistance(mesh, triangle[i], position(coord(i)));
  });

  struct Update {
    std::uint32_t triangle;
    double distance;
  };
  std::vector<std::uint32_t> work(triangle.size());
  std::iota(work.begin(), work.end(), 0u);
  std::vector<Update> updates;
  std::vector<std::uint32_t> changed;
  std::vector<std::uint32_t> queued(count, 0);  // pass number that last queued the sample
  for (std::uint32_t pass = 1; !work.empty(); ++pass) {
    updates.assign(work.size(), Update{kNoTriangle, 0.0});
    tbb::parallel_for(std::size_t(0), work.size(), [&](std::size_t k) {
      const std::size_t i = work[k];
      const glm::ivec3 c = coord(i);
      const glm::dvec3 p = position(c);
      std::uint32_t best = triangle[i], tried[27];
      double bestDistance = distance[i];
      int triedCount = 0;
      forNeighbours(c, [&](std::size_t n) {
        const std::uint32_t t = triangle[n];
        if (t == kNoTriangle || t == triangle[i] ||
            std::find(tried, tried + triedCount, t) != tried + triedCount)
          return;
        tried[triedCount++] = t;
        const double d = triangleDistance(mesh, t, p);
        if (d < bestDistance || (d == bestDistance && t < best)) best = t, bestDistance = d;
      });
      if (best != triangle[i]) updates[k] = {best, bestDistance};
    });
    changed.clear();
    for (std::size_t k = 0; k < work.size(); ++k)
      if (updates[k].triangle != kNoTriangle) {
        triangle[work[k]] = updates[k].triangle;
        distance[work[k]] = updates[k].distance;
        changed.push_back(work[k]);
      }
    // Only samples next to a change can improve in the next pass.
    work.clear();
    for (std::uint32_t i : changed)
      forNeighbours(coord(i), [&](std::size_t n) {
        if (queued[n] != pass) queued[n] = pass, work.push_back(std::uint32_t(n));
      });
    std::sort(work.begin(), work.end());  // memory order, and independent of `changed`'s order
  }
}

}  // namespace sdfstream
