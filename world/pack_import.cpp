#include "world/pack_import.h"

#include "world/layout_sources.h"

#include <algorithm>
#include <atomic>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <mutex>

#include <tbb/parallel_for.h>

#include "core/error.h"
#include "world/gltf_import.h"
#include "world/mesh_source.h"
#include "world/obj_import.h"
#include "world/pack.h"
#include "world/scene_layout.h"
#include "world/tile_builder.h"
#include "world/vdb_source.h"

namespace sdfstream {
namespace {

std::string gib(double bytes) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.1f GiB", bytes / double(1ull << 30));
  return buf;
}

}  // namespace

std::vector<std::unique_ptr<SdfSource>> sourcesForInput(const std::filesystem::path& input,
                                                        double voxelSize,
                                                        const ImportLimits& /*limits*/) {
  std::string ext = input.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return char(std::tolower(c)); });
  std::vector<std::unique_ptr<SdfSource>> sources;
  if (ext == ".vdb") {
    std::vector<std::string> skipped;
    sources = makeVdbSources(input, voxelSize, &skipped);
    if (!skipped.empty()) {  // one line naming what is not imported
      std::string line = input.filename().string() + ": skipping ";
      for (std::size_t i = 0; i < skipped.size(); ++i) line += (i ? ", " : "") + skipped[i];
      std::fprintf(stderr, "%s\n", line.c_str());
    }
  } else if (ext == ".gltf" || ext == ".glb" || ext == ".obj") {
    sources.push_back(makeMeshSource(ext == ".obj" ? loadObj(input) : loadGltf(input)));
  } else if (ext == ".json") {
    // A layout is a union of sources: terrain, one mesh per placement, the boxes.
    sources = loadLayoutSources(input);
  } else {
    throw InputError(InputErrorKind::Usage, input.string(),
                     "unsupported input type '" + ext +
                         "' (expected .gltf, .glb, .obj, .json scene layout or .vdb)");
  }
  return sources;
}

PartitionSpec partitionFor(const std::vector<std::unique_ptr<SdfSource>>& sources,
                           const PackImportOptions& options, const std::string& sourceName) {
  if (sources.empty()) throw InputError(InputErrorKind::Empty, sourceName, "nothing to import");
  PartitionSpec spec;
  spec.lodCount = options.lodCount;
  spec.tileVoxels = options.tileVoxels;
  const double native = sources.front()->nativeVoxelSize();
  spec.voxelSize = options.voxelSize > 0.0 ? options.voxelSize : native;
  if (spec.voxelSize == native) spec.origin = sources.front()->nativeOrigin();
  if (!spec.valid())
    throw InputError(InputErrorKind::OutOfRange, sourceName,
                     "bad partition: voxel " + std::to_string(spec.voxelSize) + " m, " +
                         std::to_string(spec.lodCount) + " LODs (1.." +
                         std::to_string(PartitionSpec::kMaxLods) + "), tile " +
                         std::to_string(spec.tileVoxels) + " voxels (a multiple of " +
                         std::to_string(8 << std::clamp(spec.lodCount - 1, 0, 7)) + ")");
  return spec;
}

std::vector<glm::ivec3> candidateTiles(const std::vector<std::unique_ptr<SdfSource>>& sources,
                                       const PartitionSpec& spec) {
  const double grow = (layout::kNarrowBand + 1.0) * spec.lodVoxelSize(spec.lodCount - 1);
  std::vector<glm::ivec3> tiles;
  for (const auto& s : sources) {
    const glm::ivec3 lo = tileOf(spec, s->boundsMin() - grow);
    const glm::ivec3 hi = tileOf(spec, s->boundsMax() + grow);
    for (int z = lo.z; z <= hi.z; ++z)
      for (int y = lo.y; y <= hi.y; ++y)
        for (int x = lo.x; x <= hi.x; ++x) tiles.push_back({x, y, z});
  }
  std::sort(tiles.begin(), tiles.end(), brickCoordLess);
  tiles.erase(std::unique(tiles.begin(), tiles.end()), tiles.end());
  return tiles;
}

void importPack(const std::vector<std::unique_ptr<SdfSource>>& sources,
                const std::filesystem::path& out, const PartitionSpec& spec,
                const PackImportOptions& options, const std::string& sourceName) {
  if (!spec.valid()) throw InputError(InputErrorKind::Usage, sourceName, "invalid partition spec");
  if (options.shardCount < 1 || options.shardIndex < 0 || options.shardIndex >= options.shardCount)
    throw InputError(InputErrorKind::Usage, "command line",
                     "--shard i/n needs 0 <= i < n (got " + std::to_string(options.shardIndex) +
                         "/" + std::to_string(options.shardCount) + ")");
  if (sources.empty()) throw InputError(InputErrorKind::Empty, sourceName, "nothing to import");
  double estimate = 0;
  for (const auto& s : sources) estimate += s->estimateBytes(spec);
  if (estimate > double(options.limits.maxBytes))
    throw InputError(InputErrorKind::TooLarge, sourceName,
                     "voxel size " + std::to_string(spec.voxelSize) + " m with " +
                         std::to_string(spec.lodCount) + " LODs needs about " + gib(estimate) +
                         " (limit " + gib(double(options.limits.maxBytes)) +
                         "); pass a larger voxel size");

  glm::dvec3 lo(INFINITY), hi(-INFINITY);
  std::vector<std::string> materials;
  std::vector<SceneLight> lights;
  std::vector<const SdfSource*> raw;
  for (const auto& s : sources) {
    lo = glm::min(lo, s->boundsMin());
    hi = glm::max(hi, s->boundsMax());
    for (std::string& m : s->materialNames()) materials.push_back(std::move(m));
    for (const SceneLight& l : s->lights()) lights.push_back(l);
    raw.push_back(s.get());
  }
  std::vector<glm::ivec3> tiles;
  {
    const std::vector<glm::ivec3> all = candidateTiles(sources, spec);
    for (std::size_t i = 0; i < all.size(); ++i)
      if (int(i % std::size_t(options.shardCount)) == options.shardIndex) tiles.push_back(all[i]);
  }

  PackWriter writer(out, spec);  // before the slow part: a bad output path fails fast
  // LOD by LOD, all sources side by side: a mesh source builds LOD l >= 1 from its LOD l-1
  // level set (mesh_source.cpp), so LOD l-1 must be ready first (OpenVDB parallelises inside).
  for (int lod = 0; lod < spec.lodCount; ++lod)
    tbb::parallel_for(std::size_t(0), sources.size(),
                      [&](std::size_t i) { sources[i]->prepareLod(spec, lod); });
  std::mutex progressMutex;
  std::size_t done = 0;
  tbb::parallel_for(std::size_t(0), tiles.size(), [&](std::size_t i) {
    writer.addTile(buildTile(raw, spec, tiles[i]));
    if (options.progress) {
      std::lock_guard<std::mutex> lock(progressMutex);
      options.progress(++done, tiles.size());
    }
  });
  for (const auto& s : sources)
    for (int lod = 0; lod < spec.lodCount; ++lod) s->releaseLod(lod);
  writer.commit(lo, hi, sourceName, materials, lights);
}

}  // namespace sdfstream
