// Writes the seeds that only this project's own writers can make: object-cache files
// (serializeObjectSdf), an irradiance-cache file for the fuzzer's query (cachedIrradiance), and
// world packs of a small box at 1..3 LODs (importPack: manifests and tiles). Built here rather
// than by the Release tool so the seeds never depend on another build's state.
// Run by scripts/fuzz:  sdfstream_fuzz_seeds OUT_DIR  →  OUT_DIR/{object_cache,irradiance_cache,
// manifest,tile}/*
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "core/error.h"
#include "fuzz/irradiance_scene.h"
#include "objects/object_cache.h"
#include "objects/object_sdf.h"
#include "objects/primitive_meshes.h"
#include "world/mesh_source.h"
#include "world/pack_import.h"

namespace fs = std::filesystem;
using namespace sdfstream;

namespace {

void write(const fs::path& file, const std::vector<std::uint8_t>& bytes) {
  fs::create_directories(file.parent_path());
  std::ofstream(file, std::ios::binary)
      .write(reinterpret_cast<const char*>(bytes.data()), std::streamsize(bytes.size()));
}

// Coarse grids keep the seeds small (12 bytes per sample): 2..6 intervals, no padding.
void objectCacheSeeds(const fs::path& out) {
  const TriangleScene meshes[] = {
      makeBoxMesh(glm::vec3(0.5f, 0.25f, 0.5f), glm::vec4(0.8f, 0.2f, 0.2f, 1.0f), glm::vec3(1.0f)),
      makeSphereMesh(0.5f, glm::vec4(0.5f), 6)};
  int i = 0;
  for (const TriangleScene& mesh : meshes)
    for (std::uint32_t resolution : {2u, 5u}) {
      ObjectSdfSettings settings;
      settings.minResolution = settings.maxResolution = resolution;
      settings.padVoxels = resolution > 2 ? 1 : 0;
      const std::uint64_t key = objectCacheKey(mesh, settings);
      write(out / ("seed-" + std::to_string(i++) + ".osdf"),
            serializeObjectSdf(buildObjectSdf(mesh, settings), key));
    }
}

void irradianceCacheSeed(const fs::path& out) {
  const fuzz::IrradianceQuery q;
  const fs::path dir = out / "tmp";
  reference::cachedIrradiance(dir, *q.tracer, q.positions, q.normals, q.kSamples, q.kKind);
  const fs::path file = reference::irradianceCachePath(dir, *q.tracer, q.positions, q.normals,
                                                       q.kSamples, q.kKind);
  fs::copy_file(file, out / "seed-valid.bin", fs::copy_options::overwrite_existing);
  fs::remove_all(dir);
}

// Tiles of at most 8 KiB: larger ones mutate slowly and say nothing the small ones do not.
void packSeeds(const fs::path& out) {
  struct Spec {
    int lods, tileVoxels;
    double voxel;
  };
  for (const Spec& s : {Spec{1, 8, 0.25}, Spec{2, 16, 0.125}, Spec{3, 32, 0.0625}}) {
    std::vector<std::unique_ptr<SdfSource>> sources;
    sources.push_back(makeMeshSource(makeBoxMesh(glm::vec3(0.4f, 0.3f, 0.2f),
                                                 glm::vec4(0.7f, 0.5f, 0.3f, 1.0f), glm::vec3(0.0f))));
    PackImportOptions options;
    options.voxelSize = s.voxel;
    options.lodCount = s.lods;
    options.tileVoxels = s.tileVoxels;
    const PartitionSpec spec = partitionFor(sources, options, "box");
    const std::string name = "lods" + std::to_string(s.lods);
    const fs::path pack = out / "tmp" / name;
    importPack(sources, pack, spec, options, "box");
    fs::create_directories(out / "manifest");
    fs::copy_file(pack / "manifest.json", out / "manifest" / (name + ".json"),
                  fs::copy_options::overwrite_existing);
    fs::create_directories(out / "tile");
    for (const auto& tile : fs::directory_iterator(pack / "tiles"))
      if (fs::file_size(tile.path()) <= 8192)
        fs::copy_file(tile.path(), out / "tile" / (name + "_" + tile.path().filename().string()),
                      fs::copy_options::overwrite_existing);
  }
  fs::remove_all(out / "tmp");
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: %s OUT_DIR\n", argv[0]);
    return 2;
  }
  try {
    objectCacheSeeds(fs::path(argv[1]) / "object_cache");
    irradianceCacheSeed(fs::path(argv[1]) / "irradiance_cache");
    packSeeds(fs::path(argv[1]));
  } catch (const std::exception& e) {
    std::fprintf(stderr, "make_seeds: %s\n", e.what());
    return 1;
  }
  return 0;
}
