#include "world/partition.h"

#include <cmath>

namespace sdfstream {

bool PartitionSpec::valid() const {
  if (!(voxelSize > 0.0) || !std::isfinite(voxelSize)) return false;
  if (lodCount < 1 || lodCount > kMaxLods) return false;
  if (!std::isfinite(origin.x) || !std::isfinite(origin.y) || !std::isfinite(origin.z))
    return false;
  const int unit = 8 << (lodCount - 1);  // one coarsest-LOD brick, in LOD-0 voxels
  return tileVoxels > 0 && tileVoxels % unit == 0;
}

glm::ivec3 tileOf(const PartitionSpec& spec, const glm::dvec3& world) {
  // Tile t holds LOD-0 cells [t·tileVoxels, (t+1)·tileVoxels): cell = floor(index position).
  const glm::dvec3 t = glm::floor((world - spec.origin) / spec.tileSizeMeters());
  return glm::ivec3(t);
}

glm::dvec3 tileMin(const PartitionSpec& spec, glm::ivec3 tile) {
  return spec.origin + glm::dvec3(tile) * spec.tileSizeMeters();
}

glm::dvec3 tileMax(const PartitionSpec& spec, glm::ivec3 tile) {
  return spec.origin + glm::dvec3(tile + 1) * spec.tileSizeMeters();
}

}  // namespace sdfstream
