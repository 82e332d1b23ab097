#include "world/mesh_to_sdf.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <mutex>
#include <string>
#include <vector>

#include <openvdb/openvdb.h>
#include <openvdb/tools/MeshToVolume.h>

#include "core/error.h"
#include "world/closest_material.h"
#include "world/level_set_bricks.h"

namespace sdfstream {
namespace {

constexpr int kCells = int(layout::kBrickCells);

std::string formatBytes(double bytes) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.1f GiB", bytes / double(1ull << 30));
  return buf;
}

}  // namespace

void validateScene(const TriangleScene& scene) {
  if (scene.triangles.empty())
    throw InputError(InputErrorKind::Empty, scene.source, "scene holds no triangles");
  for (const glm::vec3& p : scene.positions)
    if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z))
      throw InputError(InputErrorKind::NonFinite, scene.source, "non-finite vertex position");
  for (std::size_t t = 0; t < scene.triangles.size(); ++t) {
    const glm::uvec3& tri = scene.triangles[t];
    if (std::max({tri.x, tri.y, tri.z}) >= scene.positions.size())
      throw InputError(InputErrorKind::OutOfRange, scene.source,
                       "triangle " + std::to_string(t) + " indexes a missing vertex");
  }
}

namespace {

// Whether the signs of a closed mesh's signed level set follow its triangles' orientation.
// OpenVDB's sign flood fill calls every region it cannot reach from outside the band inside:
// right for a solid, wrong for the air of a sealed room built of closed boxes (the room would
// import solid, and the GI inside it read black). Next to the middle of a triangle, the side of
// its plane a voxel lies on tells inside from outside for a consistently wound closed mesh, so
// voxels at least half a voxel from the surface whose closest point lies inside a triangle
// (every barycentric above 0.05) vote. A solid's votes agree all but a handful, or, wound inside
// out, disagree all but a handful (the flood fill's signs are right then); a sealed room's air
// or inconsistent winding gives a mix. Every 8th such voxel is asked.
bool signsFollowOrientation(const TriangleScene& scene, const openvdb::FloatGrid& distance,
                            const openvdb::Int32Grid& closest, double voxelSize) {
  auto index = closest.getConstAccessor();
  const openvdb::math::Transform& xf = distance.transform();
  std::size_t agree = 0, disagree = 0, seen = 0;
  for (auto it = distance.cbeginValueOn(); it; ++it) {
    const float d = *it;
    if (std::abs(d) < 0.5 * voxelSize || seen++ % 8 != 0) continue;
    const std::int64_t t = index.getValue(it.getCoord());
    if (t < 0 || std::uint64_t(t) >= scene.triangles.size()) continue;
    const glm::uvec3& tri = scene.triangles[std::size_t(t)];
    const glm::dvec3 a(scene.positions[tri.x]), b(scene.positions[tri.y]),
        c(scene.positions[tri.z]);
    const glm::dvec3 n = glm::cross(b - a, c - a);
    if (glm::dot(n, n) <= 0.0) continue;
    const openvdb::Vec3d w = xf.indexToWorld(it.getCoord());
    const glm::dvec3 p(w.x(), w.y(), w.z());
    const glm::dvec2 bary = closestBarycentrics(p, a, b, c);
    if (std::min({1.0 - bary.x - bary.y, bary.x, bary.y}) < 0.05) continue;
    const glm::dvec3 q = a + (b - a) * bary.x + (c - a) * bary.y;
    ((glm::dot(p - q, n) > 0.0) == (d > 0.0f) ? agree : disagree) += 1;
  }
  const std::size_t votes = agree + disagree;
  return std::min(agree, disagree) * 20 <= votes;  // at most 5% either way
}

}  // namespace

MeshLevelSet meshLevelSet(const TriangleScene& scene, bool closed, double voxelSize,
                          glm::dvec3 origin) {
  static std::once_flag once;
  std::call_once(once, [] { openvdb::initialize(); });
  std::vector<openvdb::Vec3d> points(scene.positions.size());
  for (std::size_t i = 0; i < points.size(); ++i) {
    glm::dvec3 p = (glm::dvec3(scene.positions[i]) - origin) / voxelSize;  // index space
    points[i] = openvdb::Vec3d(p.x, p.y, p.z);
  }
  std::vector<openvdb::Vec3I> polygons(scene.triangles.size());
  for (std::size_t i = 0; i < polygons.size(); ++i)
    polygons[i] = openvdb::Vec3I(scene.triangles[i].x, scene.triangles[i].y, scene.triangles[i].z);
  openvdb::tools::QuadAndTriangleDataAdapter<openvdb::Vec3d, openvdb::Vec3I> mesh(points, polygons);
  auto transform = openvdb::math::Transform::createLinearTransform(voxelSize);
  transform->postTranslate(openvdb::Vec3d(origin.x, origin.y, origin.z));
  MeshLevelSet out;
  out.closest = openvdb::Int32Grid::create(openvdb::Int32(openvdb::util::INVALID_IDX));
  const float band = layout::kNarrowBand;
  if (closed) {
    out.distance = openvdb::tools::meshToVolume<openvdb::FloatGrid>(mesh, *transform, band, band, 0,
                                                                    out.closest.get());
    out.isSigned = signsFollowOrientation(scene, *out.distance, *out.closest, voxelSize);
    if (!out.isSigned) {
      out.closest = openvdb::Int32Grid::create(openvdb::Int32(openvdb::util::INVALID_IDX));
      closed = false;
    }
  }
  if (!closed) {
    // Unsigned distance with half a voxel more band, then shifted down by half a voxel: open
    // sheets become closed shells and distances stay exact out to kNarrowBand (see header).
    const float half = float(0.5 * voxelSize);
    out.distance = openvdb::tools::meshToVolume<openvdb::FloatGrid>(
        mesh, *transform, band + 0.5f, band + 0.5f, openvdb::tools::UNSIGNED_DISTANCE_FIELD,
        out.closest.get());
    for (auto it = out.distance->beginValueOn(); it; ++it) it.setValue(*it - half);
    out.distance->tree().root().setBackground(out.distance->background() - half,
                                              /*updateChildNodes=*/true);
    out.distance->setGridClass(openvdb::GRID_LEVEL_SET);
  }
  out.closest->setTransform(transform->copy());
  return out;
}

double defaultVoxelSize(const TriangleScene& scene) {
  glm::vec3 extent = scene.boundsMax() - scene.boundsMin();
  return double(std::max({extent.x, extent.y, extent.z})) / 112.0;
}

bool isClosedMesh(const TriangleScene& scene) {
  // Weld by exact position: sort vertex ids by position, equal positions share the first id.
  std::vector<std::uint32_t> order(scene.positions.size());
  for (std::uint32_t i = 0; i < order.size(); ++i) order[i] = i;
  auto less = [&](std::uint32_t a, std::uint32_t b) {
    const glm::vec3 &p = scene.positions[a], &q = scene.positions[b];
    if (p.x != q.x) return p.x < q.x;
    if (p.y != q.y) return p.y < q.y;
    if (p.z != q.z) return p.z < q.z;
    return a < b;
  };
  std::sort(order.begin(), order.end(), less);
  std::vector<std::uint32_t> weld(scene.positions.size());
  for (std::size_t i = 0; i < order.size(); ++i)
    weld[order[i]] = (i > 0 && scene.positions[order[i]] == scene.positions[order[i - 1]])
                         ? weld[order[i - 1]]
                         : order[i];
  std::vector<std::uint64_t> edges;
  edges.reserve(scene.triangles.size() * 3);
  for (const glm::uvec3& tri : scene.triangles) {
    std::uint32_t v[3] = {weld[tri.x], weld[tri.y], weld[tri.z]};
    if (v[0] == v[1] || v[1] == v[2] || v[0] == v[2]) continue;  // degenerate: no edges
    for (int e = 0; e < 3; ++e) {
      std::uint32_t a = v[e], b = v[(e + 1) % 3];
      edges.push_back(std::uint64_t(std::min(a, b)) << 32 | std::max(a, b));
    }
  }
  if (edges.empty()) return false;
  std::sort(edges.begin(), edges.end());
  for (std::size_t i = 0; i < edges.size();) {
    std::size_t j = i;
    while (j < edges.size() && edges[j] == edges[i]) ++j;
    if (j - i != 2) return false;
    i = j;
  }
  return true;
}

double estimateMeshImportBytes(const TriangleScene& scene, double voxelSize) {
  double bandVoxels =
      scene.surfaceArea() / (voxelSize * voxelSize) * (2.0 * layout::kNarrowBand + 1.0);
  return bandVoxels * kBytesPerBandVoxel + double(scene.triangles.size()) * 64.0;
}

World meshToWorld(const TriangleScene& scene, double voxelSize, const ImportLimits& limits) {
  validateScene(scene);
  if (voxelSize == 0.0) voxelSize = defaultVoxelSize(scene);
  if (!(voxelSize > 0.0) || !std::isfinite(voxelSize)) {
    if (voxelSize == 0.0)
      throw InputError(InputErrorKind::Empty, scene.source, "all triangles are degenerate");
    throw InputError(InputErrorKind::OutOfRange, scene.source,
                     "voxel size " + std::to_string(voxelSize) + " is not a positive number");
  }
  const glm::dvec3 lo(scene.boundsMin()), hi(scene.boundsMax());
  const glm::dvec3 reach = glm::max(glm::abs(lo), glm::abs(hi));
  const double maxIndex = std::max({reach.x, reach.y, reach.z}) / voxelSize;
  const double estimate = estimateMeshImportBytes(scene, voxelSize);
  if (estimate > double(limits.maxBytes) || maxIndex > double(1 << 28))
    throw InputError(InputErrorKind::TooLarge, scene.source,
                     "voxel size " + std::to_string(voxelSize) + " m needs about " +
                         formatBytes(estimate) + " (limit " + formatBytes(double(limits.maxBytes)) +
                         "); pass a larger voxel size");

  const bool closed = isClosedMesh(scene);
  MeshLevelSet levelSet = meshLevelSet(scene, closed, voxelSize, glm::dvec3(0.0));
  const openvdb::FloatGrid::Ptr& grid = levelSet.distance;
  const openvdb::Int32Grid& indexGrid = *levelSet.closest;
  const std::vector<float> emissionScale = emitterFluxScales(scene, levelSet, voxelSize);

  const auto triangleCount = scene.triangles.size();
  World world = bricksFromLevelSet(*grid, [&](Brick& brick) {
    auto dist = grid->getConstAccessor();
    auto index = indexGrid.getConstAccessor();
    const glm::ivec3 base = brick.coord * kCells;
    for (int z = 0; z < kCells; ++z)
      for (int y = 0; y < kCells; ++y)
        for (int x = 0; x < kCells; ++x) {
          // Nearest usable sample of the 8 around the cell centre: smallest |d| with an index.
          std::int64_t best = -1;
          float bestDist = 0;
          for (int corner = 0; corner < 8; ++corner) {
            openvdb::Coord ijk(base.x + x + (corner & 1), base.y + y + (corner >> 1 & 1),
                               base.z + z + (corner >> 2));
            std::int64_t t = index.getValue(ijk);
            if (t < 0 || std::uint64_t(t) >= triangleCount) continue;
            float d = std::abs(dist.getValue(ijk));
            if (best < 0 || d < bestDist) best = t, bestDist = d;
          }
          PackedMaterial material;  // 0 / 0 when no triangle is within the band
          if (best >= 0) {
            glm::dvec3 centre = (glm::dvec3(base + glm::ivec3(x, y, z)) + 0.5) * voxelSize;
            material = closestMaterial(scene, std::uint32_t(best), centre,
                                       emissionScale[scene.triangleMaterial[std::size_t(best)]]);
          }
          brick.albedo[brickCellIndex(x, y, z)] = material.albedo;
          brick.emission[brickCellIndex(x, y, z)] = material.emission;
        }
  });
  world.source = std::filesystem::path(scene.source).filename().string();
  if (world.bricks.empty())
    throw InputError(InputErrorKind::Empty, scene.source, "no surface at this voxel size");
  return world;
}

}  // namespace sdfstream
