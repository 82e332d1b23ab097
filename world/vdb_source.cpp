#include "world/vdb_source.h"

#include <cmath>
#include <optional>

#include <openvdb/openvdb.h>
#include <openvdb/tools/GridTransformer.h>

#include "core/error.h"
#include "world/color_pack.h"
#include "world/level_set_bricks.h"

namespace sdfstream {
namespace {

class VdbSource final : public SdfSource {
 public:
  VdbSource(const std::string& file, openvdb::FloatGrid::Ptr grid, double voxelOverride,
            bool namesMaterial)
      : file_(file), grid_(std::move(grid)), namesMaterial_(namesMaterial) {
    if (!(voxelOverride >= 0.0) || !std::isfinite(voxelOverride))
      throw InputError(InputErrorKind::OutOfRange, file_, "voxel size must be positive (or 0)");
    const double own = grid_->voxelSize()[0];
    if (!(own > 0.0) || !std::isfinite(own))
      throw InputError(InputErrorKind::Truncated, file_, "corrupt transform: bad voxel size");
    voxel_ = voxelOverride > 0.0 ? voxelOverride : own;
    const openvdb::Vec3d o = grid_->transform().indexToWorld(openvdb::Vec3d(0.0));
    origin_ = glm::dvec3(o.x(), o.y(), o.z());
    const openvdb::CoordBBox box = grid_->evalActiveVoxelBoundingBox();
    if (box.empty() || grid_->activeVoxelCount() == 0)
      throw InputError(InputErrorKind::Empty, file_, "level set has no active voxel");
    // World bounds of the active index box (8 corners: the transform may rotate).
    lo_ = glm::dvec3(INFINITY), hi_ = glm::dvec3(-INFINITY);
    for (int c = 0; c < 8; ++c) {
      openvdb::Vec3d p((c & 1 ? box.max() : box.min()).x(), (c & 2 ? box.max() : box.min()).y(),
                       (c & 4 ? box.max() : box.min()).z());
      openvdb::Vec3d w = grid_->transform().indexToWorld(p);
      lo_ = glm::min(lo_, glm::dvec3(w.x(), w.y(), w.z()));
      hi_ = glm::max(hi_, glm::dvec3(w.x(), w.y(), w.z()));
    }
    grey_ = packAlbedo(glm::vec4(0.8f, 0.8f, 0.8f, 1.0f));
    // Unlabelled fallback grids too, for resampleToMatch's level-set rebuild; here rather than
    // in prepareLod, which may run for several LODs at once.
    grid_->setGridClass(openvdb::GRID_LEVEL_SET);
  }

  glm::dvec3 boundsMin() const override { return lo_; }
  glm::dvec3 boundsMax() const override { return hi_; }
  double nativeVoxelSize() const override { return voxel_; }
  glm::dvec3 nativeOrigin() const override { return origin_; }
  // One name for the whole file: the grids share the material.
  std::vector<std::string> materialNames() const override {
    return namesMaterial_ ? std::vector<std::string>{"vdb grey"} : std::vector<std::string>{};
  }

  double estimateBytes(const PartitionSpec& spec) const override {
    // A surface's band scales with the square of the resolution change.
    double bytes = 0;
    for (int l = 0; l < spec.lodCount; ++l) {
      const double ratio = grid_->voxelSize()[0] / spec.lodVoxelSize(l);
      bytes += double(grid_->activeVoxelCount()) * ratio * ratio * kBytesPerBandVoxel;
    }
    return bytes;
  }

  void prepareLod(const PartitionSpec& spec, int lod) override {
    const double v = spec.lodVoxelSize(lod);
    Lod& l = lods_.at(std::size_t(lod));
    l.voxel = v;
    if (aligned(spec.origin, v)) {
      l.grid = grid_;
      return;
    }
    // Rebuild onto the aligned grid; the output background sets the rebuilt half-width.
    auto out = openvdb::FloatGrid::create(float(layout::kNarrowBand * v));
    auto xf = openvdb::math::Transform::createLinearTransform(v);
    xf->postTranslate(openvdb::Vec3d(spec.origin.x, spec.origin.y, spec.origin.z));
    out->setTransform(xf);
    out->setGridClass(openvdb::GRID_LEVEL_SET);
    try {
      openvdb::tools::resampleToMatch<openvdb::tools::BoxSampler>(*grid_, *out);
    } catch (const std::exception& e) {
      throw InputError(InputErrorKind::Malformed, file_,
                       std::string("cannot resample level set: ") + e.what());
    }
    l.grid = out;
  }

  void releaseLod(int lod) override { lods_.at(std::size_t(lod)) = Lod{}; }

  bool sampleBrick(int lod, glm::ivec3 brick, BrickSamples& out) const override {
    const Lod& l = lods_.at(std::size_t(lod));
    auto acc = l.grid->getConstAccessor();
    std::array<float, layout::kBrickSampleCount> own;
    if (!unionLevelSetBrick(acc, brick, float(l.voxel), out, &own)) return false;
    for (int z = 0; z < 8; ++z)
      for (int y = 0; y < 8; ++y)
        for (int x = 0; x < 8; ++x) {
          float nearest = INFINITY;
          for (int c = 0; c < 8; ++c)
            nearest = std::min(nearest, std::abs(own[std::size_t(brickSampleIndex(
                                            x + (c & 1), y + (c >> 1 & 1), z + (c >> 2)))]));
          const std::size_t cell = std::size_t(brickCellIndex(x, y, z));
          if (!(nearest < out.materialDistance[cell])) continue;
          out.albedo[cell] = grey_;
          out.emission[cell] = 0;
          out.emitter[cell] = 0;
          out.materialDistance[cell] = nearest;
        }
    return true;
  }

 private:
  // The file's grid already is the aligned grid of voxel v: same scale, index 0 at the spec's
  // origin (a lattice shifted by whole voxels is rebuilt too; simpler than re-indexing a tree).
  bool aligned(glm::dvec3 origin, double v) const {
    if (!isUniformAxisAligned(grid_->transform())) return false;
    if (std::abs(grid_->voxelSize()[0] - v) > 1e-9 * v) return false;
    return glm::all(glm::lessThan(glm::abs(origin_ - origin) / v, glm::dvec3(1e-6)));
  }

  struct Lod {
    double voxel = 0;
    openvdb::FloatGrid::Ptr grid;
  };
  std::string file_;
  openvdb::FloatGrid::Ptr grid_;
  bool namesMaterial_ = true;
  double voxel_ = 0;
  glm::dvec3 origin_{0.0}, lo_{0.0}, hi_{0.0};
  std::uint32_t grey_ = 0;
  std::array<Lod, PartitionSpec::kMaxLods> lods_;
};

}  // namespace

std::vector<std::unique_ptr<SdfSource>> makeVdbSources(const std::filesystem::path& path,
                                                       double voxelOverride,
                                                       std::vector<std::string>* skipped) {
  LevelSetFile f = readLevelSetGrids(path);
  std::vector<std::unique_ptr<SdfSource>> sources;
  std::optional<InputError> firstEmpty;
  for (std::size_t i = 0; i < f.grids.size(); ++i) {
    try {
      sources.push_back(std::make_unique<VdbSource>(path.string(), f.grids[i], voxelOverride,
                                                    sources.empty()));
    } catch (const InputError& e) {
      if (e.kind() != InputErrorKind::Empty) throw;
      if (!firstEmpty) firstEmpty = e;
      f.skipped.push_back("'" + f.grids[i]->getName() + "' (empty level set)");
    }
  }
  if (sources.empty()) throw *firstEmpty;
  if (skipped) *skipped = std::move(f.skipped);
  return sources;
}

std::unique_ptr<SdfSource> makeVdbSource(const std::filesystem::path& path, double voxelOverride) {
  return std::make_unique<VdbSource>(path.string(), readLevelSetFile(path), voxelOverride, true);
}

}  // namespace sdfstream
