// The bricking step shared by mesh and .vdb import: an OpenVDB float level set (values in world
// units, uniform voxel size) → the World's 8³ bricks. Internal to world/ (includes OpenVDB).
#pragma once

#include <array>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include <openvdb/openvdb.h>

#include "world/sdf_source.h"
#include "world/triangle_scene.h"
#include "world/world.h"

namespace sdfstream {

// Fills brick.albedo / brick.emission for a brick whose coord and distances are set. Called
// concurrently from several threads, once per kept brick; must be deterministic per brick.
using BrickMaterialFn = std::function<void(Brick&)>;

// One brick per OpenVDB leaf (leaves are 8³ at multiples of 8, exactly our bricks: ARCHITECTURE.md
// "Brick"; coord = leaf origin / 8), plus bricks whose apron reaches into a leaf and bricks inside
// active tiles. A brick is kept iff one of its 9³ samples has |d| < kNarrowBand voxels, so every
// cell with a sign change has its brick. Samples are value / voxelSize clamped to ±kNarrowBand
// (non-finite values read as +kNarrowBand). Output sorted by brickCoordLess, independent of
// thread scheduling. World::origin is the world position of index (0,0,0) of grid's transform,
// which must be linear with uniform scale and no rotation (asserted by callers).
World bricksFromLevelSet(const openvdb::FloatGrid& grid, const BrickMaterialFn& material);

// Rough peak bytes per narrow-band voxel while building: the float distance and int32 index
// trees, OpenVDB's scratch trees during mesh conversion, partially filled leaves and the output
// bricks. Deliberately conservative.
inline constexpr double kBytesPerBandVoxel = 48.0;

// --- Shared by the whole-world importers and the SdfSources (mesh_source, vdb_source). ---

// A mesh's level set on the grid with voxel `voxelSize` whose index 0 sits at world `origin`, and
// OpenVDB's closest-polygon index grid (INVALID_IDX where none). Sign rule of mesh_to_sdf.h:
// closed → signed, open → unsigned minus half a voxel. Band kNarrowBand voxels (+0.5 when open).
// A closed mesh whose signs do not follow its triangles' orientation (signsFollowOrientation) is
// imported as open instead; `isSigned` says which rule was applied.
// Defined in mesh_to_sdf.cpp. The scene must have passed validation (indices in range, finite).
struct MeshLevelSet {
  openvdb::FloatGrid::Ptr distance;
  openvdb::Int32Grid::Ptr closest;
  bool isSigned = false;
};
MeshLevelSet meshLevelSet(const TriangleScene& scene, bool closed, double voxelSize,
                          glm::dvec3 origin);
// Per material, the factor on its emission that keeps an emitter's flux through the import: the
// area of its triangles over the area of the imported surface whose closest triangle is one of
// them. An open mesh imports as shells half a voxel proud of its sheets (mesh_to_sdf.h), so an
// emitter's visible area, and the light it sends into the scene, grow with the voxel: a 2.4 x 1 x
// 0.1 m panel gains 13% at 5 cm voxels and 27% at 10 cm. Imported area: from the shell's crossings
// of grid edges, only on the side its closest triangle faces (glTF's front; the back is the
// sheet's back or a hollow inside, and the rim counts). All 1 for a signed level set (its surface
// is the mesh's own) and for materials that emit nothing; clamped to [0.5, 2], 1 below 8
// crossings. The emitter then looks dimmer up close by the same factor. Defined in
// emitter_flux.cpp.
std::vector<float> emitterFluxScales(const TriangleScene& scene, const MeshLevelSet& levelSet,
                                     double voxelSize);
// Throws the InputErrors of meshToWorld's validation (Empty, NonFinite, OutOfRange).
void validateScene(const TriangleScene& scene);
// Closest point on triangle (a,b,c) to p as barycentrics (b1, b2) of b and c.
glm::dvec2 closestBarycentrics(glm::dvec3 p, glm::dvec3 a, glm::dvec3 b, glm::dvec3 c);

// The float level set vdbToWorld would import from a file (grid choice, errors and untrusted-input
// handling of vdb_import.h). Defined in vdb_import.cpp.
openvdb::FloatGrid::Ptr readLevelSetFile(const std::filesystem::path& file);
// Every float level set of a file, in file order: grids labelled GRID_LEVEL_SET and unlabelled
// float grids that look like level sets (vdb_import.h's rule); labelled[i] says which. skipped
// names every other grid as "'name' (kind)", e.g. "'density' (fog volume)". Same errors as
// readLevelSetFile (NotLevelSet when grids is empty).
struct LevelSetFile {
  std::vector<openvdb::FloatGrid::Ptr> grids;
  std::vector<bool> labelled;
  std::vector<std::string> skipped;
};
LevelSetFile readLevelSetGrids(const std::filesystem::path& file);
// Linear, axis-aligned, uniform positive scale (+ translation).
bool isUniformAxisAligned(const openvdb::math::Transform& xf);

// Min-unions LOD brick `brick` of `grid` (index i = LOD sample i) into out.distance: values /
// voxelSize, non-finite → +kNarrowBand, clamped ±kNarrowBand. own (optional) receives this grid's
// samples alone. Skips the 729 reads when no leaf lies under the brick's samples and every
// covering tile / background value is ≥ the band (returns false, own untouched then). Returns
// whether any of its samples has |d| < kNarrowBand.
bool unionLevelSetBrick(openvdb::FloatGrid::ConstAccessor& acc, glm::ivec3 brick, float voxelSize,
                        BrickSamples& out, std::array<float, layout::kBrickSampleCount>* own);

}  // namespace sdfstream
