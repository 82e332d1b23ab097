// Scene layouts: a small JSON file placing several glTF assets and boxes into one TriangleScene.
//
//   {"assets": [{"file": "chair.glb",            // relative to the layout file's directory
//                "translation": [x, y, z],        // metres, default 0
//                "rotation": [qx, qy, qz, qw],    // unit quaternion (normalized here), default id
//                "scale": [sx, sy, sz] or s,      // default 1
//                "fitSize": 1.2,                  // optional: largest bbox extent in metres
//                "onGround": true}],              // optional: lowest point moved to y = 0
//    "boxes": [{"min": [..], "max": [..], "albedo": [r, g, b], "emission": [r, g, b]}]}
//
// Per asset, fitSize (uniform scale about the asset origin) and onGround apply in the asset's own
// frame first, then world = translation * rotation * scale. Boxes are closed, 12 outward-facing
// triangles each, with their own material (albedo linear, default 0.8 grey; emission linear,
// values above 1 kept, default 0).
#pragma once

#include <filesystem>

#include "world/triangle_scene.h"

namespace sdfstream {

// Safe on untrusted input. Throws InputError naming the layout file and the key
// ("layout.json: assets[2].translation: expected 3 numbers"): Io when unreadable, Malformed for
// bad JSON (line:column given), wrong types or unknown keys, NonFinite for non-finite numbers,
// MissingData when an asset file does not exist, Empty when nothing holds a triangle. An asset's
// own import error keeps its kind and is reported as "layout.json: assets[i].file: <asset error>".
TriangleScene loadLayout(const std::filesystem::path& jsonFile);

}  // namespace sdfstream
