#include "world/mesh_source.h"

#include <cmath>
#include <limits>
#include <mutex>

#include <tbb/parallel_for.h>

#include <openvdb/tools/MeshToVolume.h>
#include <openvdb/tools/VolumeToMesh.h>

#include "world/color_pack.h"
#include "world/level_set_bricks.h"
#include "world/mesh_to_sdf.h"

namespace sdfstream {
namespace {

constexpr int kCells = int(layout::kBrickCells);
// volumeToMesh adaptivity of the coarse-LOD rebuild: merges flat stretches of the finer
// isosurface (bunny at 256 voxels across: 228k polygons at 0 -> 10k from LOD 0); coarse-LOD sign
// agreement and thin walls unchanged (tests/partition); 0.2 measured 1.85x vdb_tool, 0.5 1.7x.
constexpr double kRebuildAdaptivity = 0.5;

class MeshSource final : public SdfSource {
 public:
  explicit MeshSource(TriangleScene scene) : scene_(std::move(scene)) {
    validateScene(scene_);
    closed_ = isClosedMesh(scene_);
    boundsMin_ = glm::dvec3(scene_.boundsMin());
    boundsMax_ = glm::dvec3(scene_.boundsMax());
  }

  // Kept: the tile builder asks every source for its bounds for every tile and LOD.
  glm::dvec3 boundsMin() const override { return boundsMin_; }
  glm::dvec3 boundsMax() const override { return boundsMax_; }
  double nativeVoxelSize() const override { return defaultVoxelSize(scene_); }

  double estimateBytes(const PartitionSpec& spec) const override {
    double bytes = 0;
    for (int l = 0; l < spec.lodCount; ++l)
      bytes += estimateMeshImportBytes(scene_, spec.lodVoxelSize(l));
    return bytes;
  }

  std::vector<std::string> materialNames() const override {
    std::vector<std::string> names;
    for (const Material& m : scene_.materials) names.push_back(m.name);
    return names;
  }

  std::vector<SceneLight> lights() const override { return scene_.lights; }

  void prepareLod(const PartitionSpec& spec, int lod) override {
    Lod& l = lods_.at(std::size_t(lod));
    l.voxel = spec.lodVoxelSize(lod);
    l.origin = spec.origin;
    const Lod* finer = lod > 0 ? &lods_.at(std::size_t(lod - 1)) : nullptr;
    // Coarse LODs of a closed mesh: rebuilt from the next finer level set (its zero isosurface,
    // ~4x fewer polygons per LOD step) instead of the whole mesh again; LOD 0 and open meshes as
    // before. Falls back to the mesh when the finer LOD is not prepared on this grid.
    if (closed_ && finer && finer->levelSet.distance && finer->origin == spec.origin &&
        finer->voxel * 2.0 == l.voxel)
      l.levelSet = rebuildFrom(*finer, l.voxel, spec.origin);
    else
      l.levelSet = meshLevelSet(scene_, closed_, l.voxel, spec.origin);
    // A closed mesh whose finest signs failed the orientation check is open for every LOD.
    if (lod == 0) closed_ = l.levelSet.isSigned;
    emissionScale_.at(std::size_t(lod)) = emitterFluxScales(scene_, l.levelSet, l.voxel);
  }

  void releaseLod(int lod) override { lods_.at(std::size_t(lod)) = Lod{}; }

  float emissionRatio(int lod, std::uint32_t emitter) const override {
    if (lod <= 0 || emitter == 0 || std::size_t(lod) >= emissionScale_.size()) return 1.0f;
    const std::vector<float>& now = emissionScale_[std::size_t(lod)];
    const std::vector<float>& finer = emissionScale_[std::size_t(lod - 1)];
    if (emitter > now.size() || emitter > finer.size()) return 1.0f;
    return now[emitter - 1] / finer[emitter - 1];
  }

  bool sampleBrick(int lod, glm::ivec3 brick, BrickSamples& out) const override {
    const Lod& l = lods_.at(std::size_t(lod));
    auto dist = l.levelSet.distance->getConstAccessor();
    std::array<float, layout::kBrickSampleCount> own;
    if (!unionLevelSetBrick(dist, brick, float(l.voxel), out, &own)) return false;
    auto index = l.levelSet.closest->getConstAccessor();
    const glm::ivec3 base = brick * kCells;
    const auto triangleCount = scene_.triangles.size();
    for (int z = 0; z < kCells; ++z)
      for (int y = 0; y < kCells; ++y)
        for (int x = 0; x < kCells; ++x) {
          const int cell = brickCellIndex(x, y, z);
          // Cheap reject before any index lookup: no corner can beat the current material.
          float nearest = std::numeric_limits<float>::infinity();
          for (int c = 0; c < 8; ++c)
            nearest = std::min(nearest, std::abs(own[std::size_t(brickSampleIndex(
                                            x + (c & 1), y + (c >> 1 & 1), z + (c >> 2)))]));
          if (!(nearest < out.materialDistance[std::size_t(cell)])) continue;
          std::int64_t best = -1;
          float bestDist = 0;
          for (int c = 0; c < 8; ++c) {
            const int sx = x + (c & 1), sy = y + (c >> 1 & 1), sz = z + (c >> 2);
            std::int64_t t = index.getValue(openvdb::Coord(base.x + sx, base.y + sy, base.z + sz));
            if (t < 0 || std::uint64_t(t) >= triangleCount) continue;
            float d = std::abs(own[std::size_t(brickSampleIndex(sx, sy, sz))]);
            if (best < 0 || d < bestDist) best = t, bestDist = d;
          }
          if (best < 0 || !(bestDist < out.materialDistance[std::size_t(cell)])) continue;
          const glm::uvec3& tri = scene_.triangles[std::size_t(best)];
          const glm::dvec3 centre =
              l.origin + (glm::dvec3(base + glm::ivec3(x, y, z)) + 0.5) * l.voxel;
          const glm::vec2 bary(closestBarycentrics(centre, glm::dvec3(scene_.positions[tri.x]),
                                                   glm::dvec3(scene_.positions[tri.y]),
                                                   glm::dvec3(scene_.positions[tri.z])));
          out.albedo[std::size_t(cell)] =
              packAlbedo(sampleAlbedo(scene_, std::uint32_t(best), bary));
          const std::uint32_t material = scene_.triangleMaterial[std::size_t(best)];
          out.emission[std::size_t(cell)] =
              packRgb9e5(sampleEmission(scene_, std::uint32_t(best), bary) *
                         emissionScale_[std::size_t(lod)][material]);
          out.emitter[std::size_t(cell)] =
              scene_.materials[material].emissive != glm::vec3(0.0f) ? material + 1 : 0;
          out.materialDistance[std::size_t(cell)] = bestDist;
        }
    return true;
  }

 private:
  struct Lod {
    double voxel = 0;
    glm::dvec3 origin{0.0};
    MeshLevelSet levelSet;
  };

  // Signed level set at voxelSize (= 2 finer voxels) from the finer LOD's zero isosurface
  // (volumeToMesh with kRebuildAdaptivity, then meshToVolume with the same band and transform as
  // meshLevelSet). Closest triangle of a sample: the finer LOD's at the same point (sample i is
  // finer sample 2i) where it has one, else the rebuilt closest polygon's, mapped back to a scene
  // triangle through the finer index grid around the polygon's centroid (inside its band).
  MeshLevelSet rebuildFrom(const Lod& finer, double voxelSize, glm::dvec3 origin) const {
    std::vector<openvdb::Vec3s> points;
    std::vector<openvdb::Vec3I> triangles;
    std::vector<openvdb::Vec4I> quads;
    openvdb::tools::volumeToMesh(*finer.levelSet.distance, points, triangles, quads, 0.0,
                                 kRebuildAdaptivity);
    std::vector<openvdb::Vec3d> indexPoints(points.size());
    for (std::size_t i = 0; i < points.size(); ++i)
      indexPoints[i] = (openvdb::Vec3d(points[i]) - openvdb::Vec3d(origin.x, origin.y, origin.z)) /
                       voxelSize;
    std::vector<openvdb::Vec4I> polygons(quads);
    polygons.reserve(quads.size() + triangles.size());
    for (const openvdb::Vec3I& t : triangles)
      polygons.emplace_back(t[0], t[1], t[2], openvdb::util::INVALID_IDX);
    // Rebuilt polygon -> scene triangle, through the finer index grid near the centroid.
    const auto invalid = openvdb::Int32(openvdb::util::INVALID_IDX);
    std::vector<openvdb::Int32> triangleOf(polygons.size(), invalid);
    {
      auto index = finer.levelSet.closest->getConstAccessor();
      auto dist = finer.levelSet.distance->getConstAccessor();
      const auto triangleCount = std::int64_t(scene_.triangles.size());
      tbb::parallel_for(std::size_t(0), polygons.size(), [&](std::size_t p) {
        auto idx = index;  // accessors are not thread-safe: copy per task
        auto d = dist;
        const openvdb::Vec4I& q = polygons[p];
        const int n = q[3] == openvdb::util::INVALID_IDX ? 3 : 4;
        openvdb::Vec3d c(0.0);
        for (int k = 0; k < n; ++k) c += openvdb::Vec3d(points[q[k]]);
        c = (c / double(n) - openvdb::Vec3d(origin.x, origin.y, origin.z)) / finer.voxel;
        const openvdb::Coord f = openvdb::Coord::floor(c);
        float bestDist = 0;
        for (int k = 0; k < 8; ++k) {
          const openvdb::Coord ijk = f.offsetBy(k & 1, k >> 1 & 1, k >> 2);
          const std::int64_t t = idx.getValue(ijk);
          if (t < 0 || t >= triangleCount) continue;
          const float a = std::abs(d.getValue(ijk));
          if (triangleOf[p] == invalid || a < bestDist)
            triangleOf[p] = openvdb::Int32(t), bestDist = a;
        }
      });
    }
    openvdb::tools::QuadAndTriangleDataAdapter<openvdb::Vec3d, openvdb::Vec4I> mesh(indexPoints,
                                                                                    polygons);
    auto transform = openvdb::math::Transform::createLinearTransform(voxelSize);
    transform->postTranslate(openvdb::Vec3d(origin.x, origin.y, origin.z));
    MeshLevelSet out;
    out.isSigned = true;  // a closed surface rebuilt: signed, its emitters do not grow
    out.closest = openvdb::Int32Grid::create(openvdb::Int32(openvdb::util::INVALID_IDX));
    const float band = layout::kNarrowBand;
    out.distance = openvdb::tools::meshToVolume<openvdb::FloatGrid>(mesh, *transform, band, band,
                                                                    0, out.closest.get());
    auto fine = finer.levelSet.closest->getConstAccessor();
    const auto triangleCount = std::int64_t(scene_.triangles.size());
    for (auto it = out.closest->beginValueOn(); it; ++it) {
      const openvdb::Int32 t = fine.getValue(it.getCoord() << 1);
      if (t >= 0 && t < triangleCount) {
        it.setValue(t);
        continue;
      }
      const openvdb::Int32 p = *it;
      it.setValue(p >= 0 && std::size_t(p) < triangleOf.size() ? triangleOf[std::size_t(p)]
                                                               : invalid);
    }
    out.closest->setTransform(transform->copy());
    return out;
  }
  TriangleScene scene_;
  bool closed_ = false;
  glm::dvec3 boundsMin_{0.0}, boundsMax_{0.0};
  std::array<Lod, PartitionSpec::kMaxLods> lods_;
  // Per LOD and material: emitterFluxScales, kept past releaseLod (coarser LODs' ratios need it).
  std::array<std::vector<float>, PartitionSpec::kMaxLods> emissionScale_;
};

}  // namespace

std::unique_ptr<SdfSource> makeMeshSource(TriangleScene scene) {
  return std::make_unique<MeshSource>(std::move(scene));
}

}  // namespace sdfstream
