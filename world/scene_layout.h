// Scene layouts: a small JSON file placing assets (glTF/GLB/OBJ), boxes and a heightfield terrain.
//
//   {"assets": [{"file": "chair.glb",            // relative to the layout file's directory
//                "translation": [x, y, z],        // metres, default 0
//                "rotation": [qx, qy, qz, qw],    // unit quaternion (normalized here), default id
//                "scale": [sx, sy, sz] or s,      // default 1
//                "fitSize": 1.2,                  // optional: largest bbox extent in metres
//                "onGround": true}],              // optional: lowest point moved to y = 0
//    "instances": [{"file": "bunny.obj", "fitSize": 4, "onGround": true,   // as for assets
//                   "placements": [{"translation": [..], "rotation": [..], "scale": ..}, ...]}],
//    "boxes": [{"min": [..], "max": [..], "albedo": [r, g, b], "emission": [r, g, b]}],
//    "terrain": {"heightmap": "h.png", "metresPerPixel": 5, "heightScale": 120,
//                "origin": [x, y, z], "albedo": [r, g, b]},   // see world/heightfield_source.h
//    "comment": "..."}                                        // ignored
//
// Per asset, fitSize (uniform scale about the asset origin) and onGround apply in the asset's own
// frame first, then world = translation * rotation * scale. An instance entry is one asset file
// read once and placed many times (each placement is one asset placement). Boxes are closed, 12
// outward-facing triangles each, with their own material (albedo linear, default 0.8 grey;
// emission linear, values above 1 kept, default 0). A terrain's heightmap path is relative to the
// layout file like asset files; metresPerPixel (> 0) and heightScale (>= 0) are required.
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <glm/gtc/quaternion.hpp>

#include "world/heightfield_source.h"
#include "world/triangle_scene.h"

namespace sdfstream {

// Safe on untrusted input. Throws InputError naming the layout file and the key
// ("layout.json: assets[2].translation: expected 3 numbers"): Io when unreadable, Malformed for
// bad JSON (line:column given), wrong types or unknown keys, NonFinite for non-finite numbers,
// MissingData when an asset file does not exist, Empty when nothing holds a triangle. An asset's
// own import error keeps its kind and is reported as "layout.json: assets[i].file: <asset error>".
// Assets, instances and boxes merged into one scene. A terrain is refused (Malformed, key
// "terrain"): it needs the tiled importer, which takes loadLayoutSources (world/layout_sources.h).
TriangleScene loadLayout(const std::filesystem::path& jsonFile);

// The parsed layout, before any asset is read: what loadLayout and loadLayoutSources share.
struct LayoutPlacement {
  glm::dvec3 translation{0.0};
  glm::dquat rotation{1.0, 0.0, 0.0, 0.0};  // normalized
  glm::dvec3 scale{1.0};
};

struct LayoutAsset {
  std::filesystem::path file;  // resolved against the layout's directory; exists
  std::optional<double> fitSize;
  bool onGround = false;
  std::string key;                          // "assets[2]" or "instances[0]", for errors
  std::vector<LayoutPlacement> placements;  // one for an "assets" entry
};

struct ParsedLayout {
  std::string file;                 // the layout file, as given (error messages start with it)
  std::vector<LayoutAsset> assets;  // "assets" entries first, then "instances"
  TriangleScene boxes;              // all boxes in one scene; no triangles when there are none
  std::optional<HeightfieldDesc> terrain;
};

// Parses and validates the JSON (errors as for loadLayout; MissingData for an absent asset or
// heightmap file) without reading any asset. Empty is not checked here.
ParsedLayout parseLayout(const std::filesystem::path& jsonFile);
// Reads one asset file (OBJ by extension, else glTF/GLB); its errors keep their kind and are
// reported as "layout.json: <key>.file: <asset error>".
TriangleScene loadLayoutAsset(const ParsedLayout& layout, const LayoutAsset& asset);
// The asset-to-world transform of one placement: fitSize and onGround (computed from the asset's
// bounds) in the asset frame, then translation * rotation * scale.
glm::dmat4 placementTransform(const LayoutAsset& asset, const LayoutPlacement& placement,
                              const TriangleScene& scene);
// Appends `part` transformed by m to `out` (materials and textures re-indexed; a mirroring m
// flips the winding so faces keep facing out).
void appendTransformed(TriangleScene& out, const TriangleScene& part, const glm::dmat4& m);
// The same without materials or textures: the triangles use part's materials as already appended
// to `out` at materialBase (a second placement of the same asset in one scene).
void appendTransformedGeometry(TriangleScene& out, const TriangleScene& part, const glm::dmat4& m,
                               std::uint32_t materialBase);

}  // namespace sdfstream
