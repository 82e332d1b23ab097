#include "world/layout_sources.h"

#include <cmath>
#include <map>

#include "core/error.h"
#include "world/heightfield_source.h"
#include "world/mesh_source.h"
#include "world/scene_layout.h"

namespace sdfstream {

std::vector<std::unique_ptr<SdfSource>> loadLayoutSources(const std::filesystem::path& json) {
  const ParsedLayout layout = parseLayout(json);
  std::vector<std::unique_ptr<SdfSource>> sources;
  if (layout.terrain) {
    try {
      sources.push_back(makeHeightfieldSource(*layout.terrain));
    } catch (const InputError& e) {
      throw InputError(e.kind(), layout.file, std::string("terrain.heightmap: ") + e.what());
    }
  }
  // Keyed by the canonical path so "a/../bunny.obj" and "bunny.obj" are read once.
  std::map<std::filesystem::path, TriangleScene> cache;
  for (const LayoutAsset& asset : layout.assets) {
    std::error_code ec;
    std::filesystem::path key = std::filesystem::weakly_canonical(asset.file, ec);
    if (ec) key = asset.file;
    auto it = cache.find(key);
    if (it == cache.end()) it = cache.emplace(key, loadLayoutAsset(layout, asset)).first;
    const TriangleScene& part = it->second;
    for (std::size_t i = 0; i < asset.placements.size(); ++i) {
      TriangleScene placed;
      placed.source = part.source;
      appendTransformed(placed, part, placementTransform(asset, asset.placements[i], part));
      for (const glm::vec3& p : placed.positions)
        if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z))
          throw InputError(
              InputErrorKind::NonFinite, layout.file,
              asset.key +
                  (asset.placements.size() > 1 ? ".placements[" + std::to_string(i) + "]"
                                               : std::string()) +
                  ": a transformed vertex is not finite");
      sources.push_back(makeMeshSource(std::move(placed)));
    }
  }
  if (!layout.boxes.triangles.empty()) sources.push_back(makeMeshSource(layout.boxes));
  if (sources.empty())
    throw InputError(InputErrorKind::Empty, layout.file, "no assets, boxes or terrain");
  return sources;
}

}  // namespace sdfstream
