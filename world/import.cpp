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

namespace {
std::string lowerExtension(const std::filesystem::path& input) {
  std::string ext = input.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return char(std::tolower(c)); });
  return ext;
}
bool isMeshScene(const std::string& ext) {
  return ext == ".gltf" || ext == ".glb" || ext == ".obj" || ext == ".json";
}
}  // namespace

TriangleScene loadTriangles(const std::filesystem::path& input) {
  const std::string ext = lowerExtension(input);
  if (!isMeshScene(ext))
    throw InputError(InputErrorKind::Usage, input.string(),
                     "unsupported mesh scene type '" + ext +
                         "' (expected .gltf, .glb, .obj or .json scene layout)");
  return ext == ".json" ? loadLayout(input) : ext == ".obj" ? loadObj(input) : loadGltf(input);
}

World importScene(const std::filesystem::path& input, const ImportOptions& options) {
  const std::string ext = lowerExtension(input);
  World world;
  if (ext == ".vdb") {
    world = vdbToWorld(input, options.voxelSize, options.limits);
  } else if (isMeshScene(ext)) {
    world = meshToWorld(loadTriangles(input), options.voxelSize, options.limits);
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
