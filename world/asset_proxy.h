// Light stand-ins for dense models: a scene simplified to a triangle budget and written as OBJ +
// MTL with flat colours. A Sweet Home 3D tree has 13k-133k triangles of leaf cards; a kilometre
// world places thousands of them and the layout importer keeps one transformed copy per placement
// (world/layout_sources.h), so at 1 m voxels, where a tree is a dozen voxels tall, a few thousand
// triangles say the same and keep the import to minutes.
#pragma once

#include <cstddef>
#include <filesystem>

#include "world/triangle_scene.h"

namespace sdfstream {

// Simplifies each material's triangles to its share of about `targetTriangles` with
// meshoptimizer's sloppy simplifier (vertex clustering: leaf-card soups have no edges to collapse)
// and writes `obj` plus a library beside it (same stem, .mtl) whose Kd/Ke are each material's
// flat colour and emission (world/obj_import.h reads them back). Returns the triangles written.
// Throws InputError(Io) naming the file it cannot write.
std::size_t writeProxyObj(const TriangleScene& scene, std::size_t targetTriangles,
                          const std::filesystem::path& obj);

}  // namespace sdfstream
