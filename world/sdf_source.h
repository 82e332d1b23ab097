// Something the tile builder can sample a signed distance and material from, at any LOD: a
// mesh's OpenVDB level set, a .vdb grid, a heightfield terrain. A world is the union (minimum
// distance) of its sources, so a layout of many assets never needs one giant grid.
#pragma once

#include <array>
#include <cstdint>
#include <memory>

#include <glm/glm.hpp>

#include "world/partition.h"
#include "world/world.h"

namespace sdfstream {

// The 9³ distance samples and 8³ cell materials of one brick, before fp16 packing.
struct BrickSamples {
  std::array<float, layout::kBrickSampleCount> distance;  // LOD voxel units, clamped ±kNarrowBand
  std::array<std::uint32_t, layout::kBrickMaterialCount> albedo;    // RGBA8 sRGB
  std::array<std::uint32_t, layout::kBrickMaterialCount> emission;  // RGB9E5
  // |distance| of the surface sample each cell's material came from (for the union's choice).
  std::array<float, layout::kBrickMaterialCount> materialDistance;
};

class SdfSource {
 public:
  virtual ~SdfSource() = default;
  // World-space bounds of the surface, grown by nothing: the builder adds the band itself.
  virtual glm::dvec3 boundsMin() const = 0;
  virtual glm::dvec3 boundsMax() const = 0;
  // Prepares whatever sampling at this LOD needs (e.g. builds the level set at v0·2^lod on the
  // spec's aligned grid). Called once per LOD before any sampleBrick at that LOD; may be slow.
  virtual void prepareLod(const PartitionSpec& spec, int lod) = 0;
  // Writes this source's samples for LOD-l brick `brick` into out, taking the minimum with
  // what out already holds (union). Cells whose nearest surface belongs to this source get its
  // material. Returns false if the source has nothing within the band of this brick.
  // Thread-safe for concurrent calls after prepareLod.
  virtual bool sampleBrick(int lod, glm::ivec3 brick, BrickSamples& out) const = 0;
  // Releases the LOD's data once all tiles are done with it.
  virtual void releaseLod(int lod) = 0;
};

}  // namespace sdfstream
