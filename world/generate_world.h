// The large built-in world of `sdfstream generate-world`: a layout (world/scene_layout.h) for a
// kilometre world made of real Debian-packaged data: a trigger-rally-data heightmap as terrain;
// settlements (world/world_plan.h): villages of box-built houses along roads with emissive street
// lamps and parked cars, a hall to fly into, forests of Sweet Home 3D trees (as light stand-ins,
// world/asset_proxy.h); and the glmark2 bunny, assimp's 2CylinderEngine and BoxTextured and Sweet
// Home 3D's CC0 furniture scattered between them. Also the showcase flight over it (flight.txt,
// for `fly --path`). Deterministic for a seed: positions come from SplitMixRng
// (core/split_mix_rng.h), not from <random>'s distributions (whose output differs between
// standard libraries).
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
  bool settlements = true;       // villages, roads, the hall, forests and flight.txt
};

// Settlements need room for the showcase (a forest, a village and the hall, 500 m long).
constexpr double kMinSettlementWorldMetres = 1500.0;

// What was written, for the command's summary.
struct GeneratedWorld {
  std::filesystem::path layout;  // dir/layout.json
  int widthPixels = 0, heightPixels = 0;
  double sourceMetresPerPixel = 0.0;  // the map's own scale (trigger-rally data)
  double metresPerPixel = 0.0;        // stretched so the width spans sizeKm
  int placements = 0;
  std::size_t assets = 0;
  int villages = 0, houses = 0, lamps = 0;
  std::size_t boxes = 0;
  std::filesystem::path flight;  // dir/flight.txt, or empty without settlements
  bool furniture = false;        // the furniture package was installed and used
  std::string note;              // "" or one line about a non-square heightmap
};

// Extracts the heightmap (and the models) from their packages' zip files into dir and writes
// dir/layout.json (and dir/flight.txt). Throws InputError (MissingData) naming the package file
// when one is absent, (Usage) for settlements in a world under kMinSettlementWorldMetres, (Io)
// when a file cannot be written.
GeneratedWorld generateWorld(const GenerateWorldOptions& options);

}  // namespace sdfstream
