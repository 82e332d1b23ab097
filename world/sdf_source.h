// Something the tile builder can sample a signed distance and material from, at any LOD: a
// mesh's OpenVDB level set, a .vdb grid, a heightfield terrain. A world is the union (minimum
// distance) of its sources, so a layout of many assets never needs one giant grid.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "world/partition.h"
#include "world/scene_lights.h"
#include "world/world.h"

namespace sdfstream {

// The 9³ distance samples and 8³ cell materials of one brick, before fp16 packing. The builder
// starts every brick at distance +kNarrowBand (nothing), albedo/emission 0 and materialDistance
// +infinity when it wants materials, or 0 when it needs distances only (a source then computes no
// material at all: its |d| is never smaller than 0).
struct BrickSamples {
  std::array<float, layout::kBrickSampleCount> distance;  // LOD voxel units, clamped ±kNarrowBand
  std::array<std::uint32_t, layout::kBrickMaterialCount> albedo;    // RGBA8 sRGB
  std::array<std::uint32_t, layout::kBrickMaterialCount> emission;  // RGB9E5
  // |distance| of the surface sample each cell's material came from (for the union's choice).
  std::array<float, layout::kBrickMaterialCount> materialDistance;
  // Which of the source's emitters the cell's emission came from (0: none): a source that writes
  // a cell's material writes this too. The tile builder hands it back to the same source's
  // emissionRatio when a coarser LOD inherits the cell.
  std::array<std::uint32_t, layout::kBrickMaterialCount> emitter;
};

class SdfSource {
 public:
  virtual ~SdfSource() = default;
  // World-space bounds of the surface, grown by nothing: the builder adds the band itself.
  virtual glm::dvec3 boundsMin() const = 0;
  virtual glm::dvec3 boundsMax() const = 0;
  // Prepares whatever sampling at this LOD needs (e.g. builds the level set at v0·2^lod on the
  // spec's aligned grid). Called once per LOD before any sampleBrick at that LOD; may be slow.
  // LODs are prepared in order (a mesh source derives LOD l from its LOD l-1 level set); calls
  // for different sources at the same LOD may run concurrently.
  virtual void prepareLod(const PartitionSpec& spec, int lod) = 0;
  // Writes this source's samples for LOD-l brick `brick` (samples 8·brick .. 8·brick+8 of the
  // LOD-l grid, in LOD-l voxel units, clamped ±kNarrowBand) into out, taking the minimum with
  // what out already holds (union). A cell takes this source's material when this source's |d|
  // at the cell's nearest sample (of its 8 corners) is smaller than out.materialDistance[cell],
  // which is then lowered to it. Returns false if the source has nothing within the band of this
  // brick (it may still have lowered samples to -kNarrowBand: a brick wholly inside).
  // Thread-safe for concurrent calls after prepareLod.
  //
  // LOD contract (relied on by the tile builder's empty-space data, tile_builder.h): wherever a
  // surface exists at LOD 0, LOD l reports |d| < kNarrowBand at every LOD-l sample within 2.5
  // LOD-l voxels of it, even if LOD l cannot resolve the surface's sign (a wall thinner than a
  // LOD-l voxel). An unsigned-distance band around the triangles, as OpenVDB's meshToVolume and
  // level-set rebuild compute, satisfies it.
  virtual bool sampleBrick(int lod, glm::ivec3 brick, BrickSamples& out) const = 0;
  // Releases the LOD's data once all tiles are done with it.
  virtual void releaseLod(int lod) = 0;

  // Optional hints, with neutral defaults.
  // Preferred LOD-0 voxel size (0 = none) and grid origin: a .vdb grid's own, so importing it
  // without --voxel reproduces its values exactly.
  virtual double nativeVoxelSize() const { return 0.0; }
  virtual glm::dvec3 nativeOrigin() const { return glm::dvec3(0.0); }
  // Estimated peak bytes of prepareLod for LODs 0..spec.lodCount-1 held together (importPack
  // refuses with TooLarge above ImportLimits::maxBytes before any work).
  virtual double estimateBytes(const PartitionSpec& /*spec*/) const { return 0.0; }
  // The factor between an emitter's emission at LOD lod and at LOD lod - 1, for a coarse cell that
  // inherits a finer cell's material (tile_builder.h): a source whose emitters' surfaces grow with
  // the voxel scales each LOD's emission to keep their flux (mesh_source: emitterFluxScales).
  virtual float emissionRatio(int /*lod*/, std::uint32_t /*emitter*/) const { return 1.0f; }
  // Material names for the pack manifest (informational).
  virtual std::vector<std::string> materialNames() const { return {}; }
  // The source's own lights in world space (a glTF file's KHR_lights_punctual), for the manifest.
  virtual std::vector<SceneLight> lights() const { return {}; }
};

}  // namespace sdfstream
