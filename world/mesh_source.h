// A triangle mesh as an SdfSource (sdf_source.h): OpenVDB level sets built per LOD on the
// partition's aligned grid, materials from the closest triangle.
#pragma once

#include <memory>

#include "world/sdf_source.h"
#include "world/triangle_scene.h"

namespace sdfstream {

// prepareLod(spec, l) builds the level set at voxel v_l = spec.lodVoxelSize(l) with index 0 at
// spec.origin (so LOD-l sample i is grid index i), by mesh_to_sdf.h's rules: closed mesh → signed,
// open → unsigned minus half a voxel; band kNarrowBand voxels; with OpenVDB's closest-polygon
// grid. Memory per LOD ≈ estimateMeshImportBytes(scene, v_l); the scene is kept for materials.
// sampleBrick: distances min-unioned; a cell's material comes from the triangle closest to the
// cell's nearest corner sample (smallest |d| with a triangle), evaluated at the closest point to
// the cell centre (sampleAlbedo / sampleEmission), stored RGBA8 sRGB / RGB9E5.
// Throws InputError (scene.source) for an invalid scene (validateScene: Empty, NonFinite,
// OutOfRange). Deterministic; prepareLod uses all cores.
std::unique_ptr<SdfSource> makeMeshSource(TriangleScene scene);

}  // namespace sdfstream
