#include "world/mesh_source.h"

#include <cmath>
#include <limits>
#include <mutex>

#include "world/color_pack.h"
#include "world/level_set_bricks.h"
#include "world/mesh_to_sdf.h"

namespace sdfstream {
namespace {

constexpr int kCells = int(layout::kBrickCells);

class MeshSource final : public SdfSource {
 public:
  explicit MeshSource(TriangleScene scene) : scene_(std::move(scene)) {
    validateScene(scene_);
    closed_ = isClosedMesh(scene_);
  }

  glm::dvec3 boundsMin() const override { return glm::dvec3(scene_.boundsMin()); }
  glm::dvec3 boundsMax() const override { return glm::dvec3(scene_.boundsMax()); }
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

  void prepareLod(const PartitionSpec& spec, int lod) override {
    Lod& l = lods_.at(std::size_t(lod));
    l.voxel = spec.lodVoxelSize(lod);
    l.origin = spec.origin;
    l.levelSet = meshLevelSet(scene_, closed_, l.voxel, spec.origin);
  }

  void releaseLod(int lod) override { lods_.at(std::size_t(lod)) = Lod{}; }

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
          out.emission[std::size_t(cell)] =
              packRgb9e5(sampleEmission(scene_, std::uint32_t(best), bary));
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
  TriangleScene scene_;
  bool closed_ = false;
  std::array<Lod, PartitionSpec::kMaxLods> lods_;
};

}  // namespace

std::unique_ptr<SdfSource> makeMeshSource(TriangleScene scene) {
  return std::make_unique<MeshSource>(std::move(scene));
}

}  // namespace sdfstream
