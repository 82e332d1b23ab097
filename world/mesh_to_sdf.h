// Triangles → narrow-band SDF bricks with materials (OpenVDB tools::meshToVolume).
#pragma once

#include "world/import_limits.h"
#include "world/triangle_scene.h"
#include "world/world.h"

namespace sdfstream {

// Default voxel size (metres) when the user passes 0: the largest bounding-box extent / 112, so the
// whole scene plus its narrow band fits one 128³ cascade (docs/DECISIONS.md).
double defaultVoxelSize(const TriangleScene& scene);

// True when, after welding vertices with bit-identical positions, every edge of a non-degenerate
// triangle is shared by exactly two triangles (a closed, 2-manifold-by-edges surface).
bool isClosedMesh(const TriangleScene& scene);

// Estimated peak bytes of meshToWorld at this voxel size: narrow-band voxels ≈ surface area /
// voxelSize² × (2·kNarrowBand + 1), times kBytesPerBandVoxel (level_set_bricks.h).
double estimateMeshImportBytes(const TriangleScene& scene, double voxelSize);

// Converts a scene to bricks at voxelSize metres (0 = defaultVoxelSize). World origin is the world
// point (0,0,0); voxel (i,j,k) sits at voxelSize·(i,j,k).
//
// Sign rule:
//  - closed mesh (isClosedMesh): the signed level set, negative inside, |d| exact within
//    kNarrowBand voxels of the surface, provided its signs follow the triangles' orientation
//    (OpenVDB's flood fill calls the air of a sealed room made of closed boxes inside; so does
//    inconsistent winding): where they do not, the open rule below;
//  - otherwise (open sheets such as a ground quad or Sponza's planes, which have no inside): the
//    unsigned distance minus half a voxel, i.e. every open surface becomes a thin closed shell,
//    1 voxel thick, whose zero crossing lies within 0.5 voxel of the original sheet.
// Materials: for each cell centre, the closest triangle (OpenVDB's closest-polygon index at the
// cell corner with the smallest |d|), the closest point on it, sampleAlbedo / sampleEmission there;
// albedo stored as sRGB RGBA8, emission as RGB9E5. Cells with no triangle within the band get 0.
//
// Errors (InputError, file = scene.source): Empty (no triangles / zero extent), OutOfRange
// (vertex index or voxel size invalid), NonFinite (position), TooLarge (estimate above
// limits.maxBytes, or index coordinates beyond ±2^28). Uses all cores (TBB); deterministic.
World meshToWorld(const TriangleScene& scene, double voxelSize, const ImportLimits& limits);

}  // namespace sdfstream
