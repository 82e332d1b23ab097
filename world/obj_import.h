// Minimal Wavefront OBJ import: positions, faces and flat materials. Exists so layouts can place
// Debian's glmark2-data bunny and Sweet Home 3D's furniture without a conversion tool.
// Safe on untrusted input: every index is checked, every number must be finite.
//
// Materials: `usemtl NAME` selects a material defined by `newmtl NAME` in the files named by
// `mtllib` (relative to the OBJ). Its base colour is Kd (linear RGB; 0.8 grey when absent),
// multiplied by the mean colour of its `map_Kd` texture at its faces' texture-coordinate centroids
// when the texture is readable (so a textured model keeps its overall colours at SDF resolution,
// and an atlas shared by leaves and bark gives each its part; the importer keeps no UVs);
// Ke is its emission. An absent or unreadable library, an unknown material name and an
// unreadable texture fall back to the grey default, as viewers do; a malformed number in a
// library is an error naming that file and line. Faces before any usemtl use the grey default.
// Libraries and textures are read only when they are regular files (not devices or FIFOs).
#pragma once

#include <filesystem>

#include "world/triangle_scene.h"

namespace sdfstream {

// Throws InputError (Io, Malformed, OutOfRange, NonFinite, Empty) naming the file and line.
TriangleScene loadObj(const std::filesystem::path& path);

}  // namespace sdfstream
