// Command-line-facing import: any supported input file → World, or → a world directory.
#pragma once

#include <filesystem>

#include "world/import_limits.h"
#include "world/triangle_scene.h"
#include "world/world.h"

namespace sdfstream {

struct ImportOptions {
  double voxelSize = 0;  // metres; 0 = defaultVoxelSize (meshes) or the grid's own (.vdb)
  ImportLimits limits;
  int lodCount = 4;  // importToDirectory only (pack_import.h)
  int tileVoxels = 128;
};

// A mesh scene's triangles by extension (case-insensitive): .gltf/.glb → loadGltf, .obj →
// loadObj, .json → loadLayout; anything else → InputError(Usage).
TriangleScene loadTriangles(const std::filesystem::path& input);

// Dispatches on the extension (case-insensitive): .gltf/.glb → loadGltf, .obj → loadObj,
// .json → loadLayout, then meshToWorld; .vdb → vdbToWorld. Unknown extension → InputError(Usage).
// Other errors as documented by those functions.
World importScene(const std::filesystem::path& input, const ImportOptions& options);

// sourcesForInput + partitionFor + importPack (pack_import.h): writes a world pack. The output
// directory appears only when everything succeeded: a failure leaves no new directory, an
// existing one intact, and no temp directory behind (PackWriter's guarantee).
void importToDirectory(const std::filesystem::path& input, const std::filesystem::path& outDir,
                       const ImportOptions& options);

}  // namespace sdfstream
