// The large built-in world of `sdfstream generate-world`: a layout (world/scene_layout.h) for a
// kilometre world made of real Debian-packaged data: a trigger-rally-data heightmap as terrain,
// with the glmark2 bunny, assimp's 2CylinderEngine and BoxTextured, and (when installed) Sweet
// Home 3D's CC0 furniture scattered on it. Deterministic for a seed: positions come from
// SplitMixRng (core/split_mix_rng.h), not from <random>'s distributions (whose output differs
// between standard libraries).
#pragma once

#include <filesystem>
#include <string>

namespace sdfstream {

struct GenerateWorldOptions {
  std::filesystem::path dir;     // output: layout.json, terrain/ and assets/ (created)
  double sizeKm = 4.0;           // side of the square world, (0, 1000]
  double heightScale = 120.0;    // metres of the heightmap's full range, >= 0
  int seed = 1;                  // placement seed, >= 0
  std::string map = "altitude";  // trigger-rally map whose h.png is the terrain
  bool furniture = true;         // scatter sweethome3d-furniture's CC0 models when installed
};

// What was written, for the command's summary.
struct GeneratedWorld {
  std::filesystem::path layout;  // dir/layout.json
  int widthPixels = 0, heightPixels = 0;
  double sourceMetresPerPixel = 0.0;  // the map's own scale (trigger-rally data)
  double metresPerPixel = 0.0;        // stretched so the width spans sizeKm
  int placements = 0;
  std::size_t assets = 0;
  bool furniture = false;  // the furniture package was installed and used
  std::string note;        // "" or one line about a non-square heightmap
};

// Extracts the heightmap (and furniture OBJs) from their packages' zip files into dir and writes
// dir/layout.json. Throws InputError (MissingData) naming the package file when one is absent,
// (Io) when a file cannot be written.
GeneratedWorld generateWorld(const GenerateWorldOptions& options);

}  // namespace sdfstream
