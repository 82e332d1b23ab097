// Internal to the glTF importer: EXT_meshopt_compression (gltfpack -c / -cc), decoded with
// Debian's libmeshoptimizer. Spec: KhronosGroup/glTF extensions/2.0/Vendor/EXT_meshopt_compression.
#pragma once

#include <cstddef>
#include <string>

#include "world/gltf_document.h"

namespace sdfstream::gltf {

// The most bytes all compressed bufferViews of one file may decode to, and the most one view may
// decode to per compressed byte. The meshopt codecs cannot expand data more than about 64× (an
// attribute stream spends at least 2 header bits per byte lane of 16 vertices; an index sequence
// a byte per index), so 256× only refuses what would fail to decode anyway, before allocating.
inline constexpr std::size_t kMaxMeshoptDecodedBytes = std::size_t(1) << 30;
inline constexpr std::size_t kMaxMeshoptExpansion = 256;

// Replaces each buffer marked {"EXT_meshopt_compression": {"fallback": true}} by a one-byte data
// URI (tinygltf cannot load a buffer without data; nothing may read it once views are decoded).
// Returns whether the JSON changed.
bool replaceMeshoptFallbackBuffers(Json& json);

// Decodes every bufferView carrying the extension into a buffer of its own (appended to
// model.buffers) and points the view at it; then refuses any view still reading a fallback
// buffer. Throws InputError: Malformed (bad extension fields, data that does not decode),
// OutOfRange (source bytes outside their buffer), TooLarge (over the limits above).
void decodeMeshoptBufferViews(Document& doc, const std::string& file);

}  // namespace sdfstream::gltf
