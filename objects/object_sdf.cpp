#include "objects/object_sdf.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>
#include <mutex>
#include <stdexcept>
#include <string>

#include <openvdb/openvdb.h>
#include <openvdb/tools/MeshToVolume.h>
#include <tbb/parallel_for.h>

#include "core/error.h"
#include "core/hash.h"
#include "objects/closest_triangle_grid.h"
#include "world/closest_material.h"
#include "world/level_set_bricks.h"  // validateScene
#include "world/mesh_to_sdf.h"       // isClosedMesh

namespace sdfstream {
namespace {

void validateSettings(const ObjectSdfSettings& s) {
  if (s.minResolution < 1 || s.minResolution > s.maxResolution || s.maxResolution > 1024)
    throw std::invalid_argument("ObjectSdfSettings: need 1 <= minResolution (" +
                                std::to_string(s.minResolution) + ") <= maxResolution (" +
                                std::to_string(s.maxResolution) + ") <= 1024");
  if (s.padVoxels > 64)
    throw std::invalid_argument("ObjectSdfSettings: padVoxels " + std::to_string(s.padVoxels) +
                                " above 64");
  if (!std::isfinite(s.targetVoxel) || s.targetVoxel < 0)
    throw std::invalid_argument("ObjectSdfSettings: targetVoxel " + std::to_string(s.targetVoxel) +
                                " is not finite and >= 0");
}

// Bounds of the vertices triangles use (stray unused vertices must not grow the grid).
void triangleBounds(const TriangleScene& mesh, glm::vec3& lo, glm::vec3& hi) {
  lo = glm::vec3(std::numeric_limits<float>::infinity());
  hi = -lo;
  for (const glm::uvec3& t : mesh.triangles)
    for (std::uint32_t v : {t.x, t.y, t.z}) {
      lo = glm::min(lo, mesh.positions[v]);
      hi = glm::max(hi, mesh.positions[v]);
    }
}

std::uint32_t bruteForceClosest(const TriangleScene& mesh, glm::dvec3 p) {
  std::uint32_t best = 0;
  double bestDistance = std::numeric_limits<double>::infinity();
  for (std::uint32_t t = 0; t < mesh.triangles.size(); ++t)
    if (const double d = triangleDistance(mesh, t, p); d < bestDistance) best = t, bestDistance = d;
  return best;
}

}  // namespace

void validateObjectMesh(const TriangleScene& mesh) {
  validateScene(mesh);  // Empty, NonFinite, vertex OutOfRange
  if (mesh.triangleMaterial.size() != mesh.triangles.size())
    throw InputError(InputErrorKind::OutOfRange, mesh.source,
                     std::to_string(mesh.triangleMaterial.size()) + " triangle materials for " +
                         std::to_string(mesh.triangles.size()) + " triangles");
  for (std::size_t t = 0; t < mesh.triangleMaterial.size(); ++t)
    if (mesh.triangleMaterial[t] >= mesh.materials.size())
      throw InputError(InputErrorKind::OutOfRange, mesh.source,
                       "triangle " + std::to_string(t) + " uses missing material " +
                           std::to_string(mesh.triangleMaterial[t]));
  glm::vec3 lo, hi;
  triangleBounds(mesh, lo, hi);
  if (std::max({hi.x - lo.x, hi.y - lo.y, hi.z - lo.z}) <= 0.0f)
    throw InputError(InputErrorKind::Empty, mesh.source, "all triangles collapse to one point");
}

ObjectSdf objectGridFor(const TriangleScene& mesh, const ObjectSdfSettings& settings) {
  validateSettings(settings);
  ObjectSdf sdf;
  triangleBounds(mesh, sdf.meshMin, sdf.meshMax);
  const glm::dvec3 extent = glm::dvec3(sdf.meshMax) - glm::dvec3(sdf.meshMin);
  const double longest = std::max({extent.x, extent.y, extent.z});
  double resolution = settings.maxResolution;
  if (settings.targetVoxel > 0)
    resolution = std::clamp(std::ceil(longest / settings.targetVoxel),
                            double(settings.minResolution), double(settings.maxResolution));
  sdf.voxel = float(longest / resolution);
  const double voxel = sdf.voxel;  // the stored float is the truth from here on
  for (int a = 0; a < 3; ++a) {
    // The 1e-6 keeps the longest axis at exactly `resolution` intervals despite rounding.
    const double intervals = std::max(0.0, std::ceil(extent[a] / voxel - 1e-6));
    sdf.dims[a] = std::max(2u, std::uint32_t(intervals) + 1 + 2 * settings.padVoxels);
    const double centre = 0.5 * (double(sdf.meshMin[a]) + double(sdf.meshMax[a]));
    sdf.gridMin[a] = float(centre - 0.5 * voxel * double(sdf.dims[a] - 1));
  }
  return sdf;
}

ObjectSdf buildObjectSdf(const TriangleScene& mesh, const ObjectSdfSettings& settings) {
  validateObjectMesh(mesh);
  ObjectSdf sdf = objectGridFor(mesh, settings);
  sdf.closed = isClosedMesh(mesh);
  static std::once_flag once;
  std::call_once(once, [] { openvdb::initialize(); });

  // Index space of the OpenVDB grid = our grid space: sample (i,j,k) at Coord(i,j,k).
  const glm::dvec3 gridMin(sdf.gridMin);
  const double voxel = sdf.voxel;
  std::vector<openvdb::Vec3d> points(mesh.positions.size());
  for (std::size_t i = 0; i < points.size(); ++i) {
    const glm::dvec3 p = (glm::dvec3(mesh.positions[i]) - gridMin) / voxel;
    points[i] = openvdb::Vec3d(p.x, p.y, p.z);
  }
  std::vector<openvdb::Vec3I> polygons(mesh.triangles.size());
  for (std::size_t i = 0; i < polygons.size(); ++i)
    polygons[i] = openvdb::Vec3I(mesh.triangles[i].x, mesh.triangles[i].y, mesh.triangles[i].z);
  openvdb::tools::QuadAndTriangleDataAdapter<openvdb::Vec3d, openvdb::Vec3I> adapter(points,
                                                                                     polygons);
  const auto transform = openvdb::math::Transform::createLinearTransform(1.0);
  // A narrow band is enough: OpenVDB's sign flood fill still marks every interior sample, and
  // growClosestTriangles carries the band's closest polygons out to the rest of the box.
  constexpr float kBand = 2.0f;
  auto closest = openvdb::Int32Grid::create(openvdb::Int32(openvdb::util::INVALID_IDX));
  openvdb::FloatGrid::Ptr grid = openvdb::tools::meshToVolume<openvdb::FloatGrid>(
      adapter, *transform, kBand, kBand, sdf.closed ? 0 : openvdb::tools::UNSIGNED_DISTANCE_FIELD,
      closest.get());

  const std::size_t count = sdf.sampleCount();
  const GridFrame frame{sdf.dims, gridMin, voxel};
  std::vector<std::uint32_t> triangle(count, kNoTriangle);
  std::vector<std::uint8_t> inside(count);
  std::atomic<bool> seeded{false};
  tbb::parallel_for(std::uint32_t(0), sdf.dims.z, [&](std::uint32_t z) {
    auto dist = grid->getConstAccessor();
    auto index = closest->getConstAccessor();
    for (std::uint32_t y = 0; y < sdf.dims.y; ++y)
      for (std::uint32_t x = 0; x < sdf.dims.x; ++x) {
        const openvdb::Coord ijk(static_cast<int>(x), static_cast<int>(y), static_cast<int>(z));
        const std::size_t i = sdf.index(x, y, z);
        const std::int64_t t = index.getValue(ijk);
        if (t >= 0 && std::uint64_t(t) < mesh.triangles.size()) {
          triangle[i] = std::uint32_t(t);
          seeded = true;
        }
        inside[i] = sdf.closed && dist.getValue(ijk) < 0.0f;
      }
  });
  // Every mesh crosses the box, so the band always holds seeds; never rely on it blindly.
  if (!seeded) triangle[0] = bruteForceClosest(mesh, gridMin);
  grid.reset();
  closest.reset();
  std::vector<double> unsignedDistance;
  growClosestTriangles(mesh, frame, triangle, unsignedDistance);

  // Open sheets become thin closed shells (mesh_to_sdf.h's sign rule).
  const double shift = sdf.closed ? 0.0 : 0.5;
  sdf.distance.assign(count, 0.0f);
  sdf.albedo.assign(count, 0u);
  sdf.emission.assign(count, 0u);
  tbb::parallel_for(std::uint32_t(0), sdf.dims.z, [&](std::uint32_t z) {
    for (std::uint32_t y = 0; y < sdf.dims.y; ++y)
      for (std::uint32_t x = 0; x < sdf.dims.x; ++x) {
        const std::size_t i = sdf.index(x, y, z);
        const double d = unsignedDistance[i] / voxel;
        sdf.distance[i] = float((inside[i] ? -d : d) - shift);
        const PackedMaterial m =
            closestMaterial(mesh, triangle[i], gridMin + voxel * glm::dvec3(x, y, z));
        sdf.albedo[i] = m.albedo;
        sdf.emission[i] = m.emission;
      }
  });
  return sdf;
}

float ObjectSdf::sampleTrilinear(glm::vec3 objectPos) const {
  if (distance.empty()) return std::numeric_limits<float>::infinity();
  const glm::vec3 top(dims - 1u);
  const glm::vec3 g = glm::clamp((objectPos - gridMin) / voxel, glm::vec3(0.0f), top);
  const glm::uvec3 i0 = glm::min(glm::uvec3(g), glm::max(dims, 2u) - 2u);
  const glm::vec3 f = g - glm::vec3(i0);
  auto at = [&](std::uint32_t dx, std::uint32_t dy, std::uint32_t dz) {
    return distance[index(i0.x + dx, i0.y + dy, i0.z + dz)];
  };
  const float x00 = glm::mix(at(0, 0, 0), at(1, 0, 0), f.x);
  const float x10 = glm::mix(at(0, 1, 0), at(1, 1, 0), f.x);
  const float x01 = glm::mix(at(0, 0, 1), at(1, 0, 1), f.x);
  const float x11 = glm::mix(at(0, 1, 1), at(1, 1, 1), f.x);
  return glm::mix(glm::mix(x00, x10, f.y), glm::mix(x01, x11, f.y), f.z);
}

std::uint64_t ObjectSdf::contentHash() const {
  struct Header {
    glm::uvec3 dims;
    glm::vec3 gridMin;
    float voxel;
    glm::vec3 meshMin, meshMax;
    std::uint32_t closed;
  } header{dims, gridMin, voxel, meshMin, meshMax, closed ? 1u : 0u};
  static_assert(sizeof(Header) == 56, "no padding: every byte hashed is a field");
  const std::uint64_t parts[4] = {
      checksum64(&header, sizeof header),
      checksum64(distance.data(), distance.size() * sizeof(float)),
      checksum64(albedo.data(), albedo.size() * sizeof(std::uint32_t)),
      checksum64(emission.data(), emission.size() * sizeof(std::uint32_t))};
  return checksum64(parts, sizeof parts);
}

}  // namespace sdfstream
