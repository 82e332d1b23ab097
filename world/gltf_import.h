// glTF 2.0 (.gltf and .glb) → TriangleScene: every triangle of the default scene in world space,
// with base colour / emission materials and their textures.
#pragma once

#include <cstddef>
#include <filesystem>
#include <string>
#include <string_view>

#include "world/triangle_scene.h"

namespace sdfstream {

// Loads the default scene (or scene 0, or every root node when the file has no scenes), applying
// all node transforms (matrix or TRS). Triangles, strips and fans are imported; points and lines
// are skipped. Winding is flipped under mirroring transforms so it stays counter-clockwise.
//
// What real pipelines write (gltfpack's defaults and -c/-cc among them): KHR_mesh_quantization
// (8/16-bit positions and UVs, normalized or not), EXT_meshopt_compression (decoded with
// libmeshoptimizer, filters included), sparse accessors, two UV sets (TEXCOORD_0/1),
// KHR_texture_transform, KHR_materials_emissive_strength, KHR_materials_pbrSpecularGlossiness
// (its diffuse colour), KHR_lights_punctual (TriangleScene::lights, placed by their nodes).
// Any other extension in extensionsRequired is refused, naming it. NORMAL, tangents, skins,
// morph targets and animations are not read.
//
// Safe on untrusted input: the JSON is type-checked before use, every accessor is bounds-checked
// against its bufferView and buffer, every index against its vertex count, every position checked
// finite, node cycles detected without recursion; decoded sizes are bounded
// (kMaxMeshoptDecodedBytes, kMaxSparseAccessorBytes, kMaxGltfLights in world/gltf_*.h).
// Failures throw InputError with a one-line message naming the file, with kinds:
//   Io           the file cannot be opened or read
//   Malformed    bad JSON (line:column given), wrong types, node cycles, bad extension fields,
//                compressed data that does not decode
//   Unsupported  an extension in extensionsRequired that is not listed above
//   MissingData  a referenced .bin or image is absent
//   OutOfRange   an index (vertex, node, mesh, accessor, material, texture, light) points outside
//                its array
//   NonFinite    a NaN or infinite position, or a non-finite transform
//   Empty        the scene holds no triangles
//   Truncated    a .glb shorter than its header declares, or a buffer shorter than declared
//   TooLarge     over one of the decoded-size limits
//   Version      a .glb container version other than 2
// Textures are kept as RGBA8 (other channel counts and 16-bit images converted); the sampler is
// ignored (sampleAlbedo always wraps). Materials keep their glTF indices; a default grey (0.8) is
// appended when some primitive has none. Memory: the scene plus the decoded file, transiently.
TriangleScene loadGltf(const std::filesystem::path& file);

namespace detail {
// "line L, column C" for nlohmann::json::parse_error::byte (1-based offset of the last byte read)
// in text. Shared with the layout loader so both report JSON errors the same way.
std::string jsonLineColumn(std::string_view text, std::size_t byte);
}  // namespace detail

}  // namespace sdfstream
