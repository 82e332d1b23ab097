#include "world/import.h"

#include <algorithm>
#include <cctype>
#include <string>

#include "core/error.h"
#include "world/gltf_import.h"
#include "world/mesh_to_sdf.h"
#include "world/obj_import.h"
#include "world/pack_import.h"
#include "world/scene_layout.h"
#include "world/vdb_import.h"

namespace sdfstream {

World importScene(const std::filesystem::path& input, const ImportOptions& options) {
  std::string ext = input.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return char(std::tolower(c)); });
  World world;
  if (ext == ".vdb") {
    world = vdbToWorld(input, options.voxelSize, options.limits);
  } else if (ext == ".gltf" || ext == ".glb" || ext == ".obj" || ext == ".json") {
    TriangleScene scene = ext == ".json"  ? loadLayout(input)
                          : ext == ".obj" ? loadObj(input)
                                          : loadGltf(input);
    world = meshToWorld(scene, options.voxelSize, options.limits);
  } else {
    throw InputError(InputErrorKind::Usage, input.string(),
                     "unsupported input type '" + ext +
                         "' (expected .gltf, .glb, .obj, .json scene layout or .vdb)");
  }
  world.source = input.filename().string();
  return world;
}

void importToDirectory(const std::filesystem::path& input, const std::filesystem::path& outDir,
                       const ImportOptions& options) {
  PackImportOptions pack;
  pack.voxelSize = options.voxelSize;
  pack.lodCount = options.lodCount;
  pack.tileVoxels = options.tileVoxels;
  pack.limits = options.limits;
  auto sources = sourcesForInput(input, options.voxelSize, options.limits);
  const std::string name = input.filename().string();
  importPack(sources, outDir, partitionFor(sources, pack, name), pack, name);
}

}  // namespace sdfstream
