// A layout file (world/scene_layout.h) as SdfSources for the tiled world importer: mesh sources
// for the asset placements (world/mesh_source.h; one per placement of a closed asset, one per
// 256 m cell for an open asset's placements, whose union is the same SDF), one for all boxes, one
// heightfield source for the terrain. Sources are independent, so a kilometre layout never needs one giant grid.
#pragma once

#include <filesystem>
#include <memory>
#include <vector>

#include "world/sdf_source.h"

namespace sdfstream {

// Each distinct asset file is read once, however many placements reference it; each placement
// gets its own transformed copy of the triangles (memory: triangles × placements). Throws
// InputError naming the layout file and the key (see loadLayout), plus the heightmap's errors
// as "layout.json: terrain.heightmap: <error>", and Empty when the layout places nothing.
std::vector<std::unique_ptr<SdfSource>> loadLayoutSources(const std::filesystem::path& json);

}  // namespace sdfstream
