#include "world/layout_sources.h"

#include <cmath>
#include <map>
#include <utility>

#include "core/error.h"
#include "world/heightfield_source.h"
#include "world/mesh_source.h"
#include "world/mesh_to_sdf.h"
#include "world/scene_layout.h"

namespace sdfstream {
namespace {

constexpr double kGroupCellMetres = 256.0;

}  // namespace

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
    // An open asset's placements in one kGroupCellMetres cell share one source: an open mesh's
    // SDF is its unsigned distance, so one source over several copies is the min of theirs (a
    // 200-tree test gave the same brick count; 6 of 648 tiles differed where copies overlap),
    // while each source costs its OpenVDB grids' fixed size per LOD (~3 MB over six
    // LODs: a forest of thousands of trees would need tens of GB). A closed asset keeps a source
    // per placement: the signed level set of overlapping closed copies is not their union.
    const bool shareSources = !isClosedMesh(part);
    std::map<std::pair<long, long>, TriangleScene> cells;
    std::vector<std::pair<long, long>> order;
    for (std::size_t i = 0; i < asset.placements.size(); ++i) {
      const glm::dmat4 m = placementTransform(asset, asset.placements[i], part);
      const glm::dvec3 at = asset.placements[i].translation;
      const auto key = shareSources && std::isfinite(at.x) && std::isfinite(at.z)
                           ? std::pair<long, long>(long(std::floor(at.x / kGroupCellMetres)),
                                                   long(std::floor(at.z / kGroupCellMetres)))
                           : std::pair<long, long>(long(i), -1L - long(i));
      auto [cell, added] = cells.try_emplace(key);
      TriangleScene& placed = cell->second;
      const std::size_t firstVertex = placed.positions.size();
      if (added) {
        order.push_back(key);
        placed.source = part.source;
        appendTransformed(placed, part, m);
      } else {
        appendTransformedGeometry(placed, part, m, 0);
      }
      for (std::size_t v = firstVertex; v < placed.positions.size(); ++v) {
        const glm::vec3& p = placed.positions[v];
        if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z))
          throw InputError(
              InputErrorKind::NonFinite, layout.file,
              asset.key +
                  (asset.placements.size() > 1 ? ".placements[" + std::to_string(i) + "]"
                                               : std::string()) +
                  ": a transformed vertex is not finite");
      }
    }
    for (const auto& key : order) sources.push_back(makeMeshSource(std::move(cells[key])));
  }
  if (!layout.boxes.triangles.empty()) sources.push_back(makeMeshSource(layout.boxes));
  if (sources.empty())
    throw InputError(InputErrorKind::Empty, layout.file, "no assets, boxes or terrain");
  return sources;
}

}  // namespace sdfstream
