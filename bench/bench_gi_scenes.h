// The scenes of `sdfstream bench gi`: each as source triangles (for the path
// traced reference and the peers), lights and sky in world units, views, and a streamed cascade
// stack over a world pack imported from those triangles (cached on disk by source).
//
//   cornell-box     ../shared/data/cornell-box/CornellBox-Original.glb when present, else built
//                   in code from the Cornell University measurements (graphics.cornell.edu
//                   /online/box/data.html, millimetres -> metres) with McGuire's RGB reflectances.
//                   The ceiling light is a downward spot light (cone 0..90 degrees) 2.5% of the box
//                   height below the light quad's centre, of on-axis intensity Ke x quad area
//                   (Ke = 17 12 4, the data's emission); the quad keeps its albedo and loses its
//                   emission, so direct light is a delta light the probes do not store (DDGI's
//                   split).
//   sponza          ../shared/data/sponza (CapsaicinTestMedia): sun through the open roof + sky.
//   breakfast-room  ../shared/data/breakfast-room: sun through the windows + sky.
//   courtyard       built in code: a 16 m court open to the sky inside a covered arcade, sky only,
//                   24.8 m across at 5 cm voxels (4 cascades): Sponza's geometry in small.
//   emissive-room   built in code: a closed 6 x 3 x 8 m room lit only by emissive surfaces (two
//                   hanging panels, a blue screen), no sun, black sky; 5 cm voxels, 2 cascades.
//   bunny           glmark2's bunny on a ground slab under sun + sky (Debian glmark2-data): the
//                   small scene quick mode uses when the Breakfast Room is absent.
//   large-world     out/worlds/village-4km (sdfstream generate-world + bench world): timings and
//                   memory only; it has no triangle reference (its terrain is a heightfield
//                   source), so its error columns stay empty.
// Views: the cameras stored in the glTF files where they have some, else placed from the bounds.
#pragma once

#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "reference/path_tracer.h"
#include "streaming/cascade_stack.h"
#include "streaming/pack_store.h"
#include "streaming/tile_loader.h"
#include "world/scene_lights.h"
#include "world/triangle_scene.h"

namespace sdfstream::bench {

struct BenchScene {
  std::string name;                          // "cornell-box"
  std::string description;                   // one line for the summary: source, lighting
  std::unique_ptr<TriangleScene> triangles;  // null for the large world
  SceneLights lights;
  std::filesystem::path packSource;  // what the pack is imported from (cache key), or a pack
  bool prebuiltPack = false;         // packSource is a pack already (large world)
  double voxelSize = 0.0;            // LOD-0 voxel, metres
  int lods = 4;                      // pack LODs = the most cascades a sweep may ask for
  int defaultCascades = 3;           // "our default" cascade count on this scene
  std::vector<int> cascadeSweep;     // cascade counts the sweep tries
  glm::dvec3 streamCamera{0.0};      // where the stack is centred (the player)
  glm::vec3 viewDirection{0.0f, 0.0f, -1.0f};
  std::vector<reference::PinholeCamera> views;
  std::vector<std::string> viewNames;
};

// Every scene name loadBenchScene knows, in the order a full run uses.
const std::vector<std::string>& benchSceneNames();

// Scenes by name (cornell-box, sponza, breakfast-room, courtyard, emissive-room, bunny,
// large-world), or NAME@VIEW: the scene with that view alone (its name or index) and the player,
// where the stack is centred, at that view's camera. Returns nullopt and sets *skip to a
// one-line reason when the scene's data or the view is absent. dataDir is ../shared/data.
std::optional<BenchScene> loadBenchScene(const std::string& name,
                                         const std::filesystem::path& dataDir,
                                         const std::filesystem::path& largeWorld,
                                         std::string* skip);

// The pack for a scene under cacheDir/<name>-<key> (key: XXH3 of the source file bytes' size and
// mtime, voxel size and LODs; for built-in scenes, the triangles), imported when missing. Returns
// the pack directory and sets *imported (seconds spent importing, 0 when cached).
std::filesystem::path benchScenePack(const BenchScene& scene, const std::filesystem::path& cacheDir,
                                     double* importSeconds);

// A cascade stack of `cascades` cascades over a pack, settled around the scene's stream camera.
struct StreamedStack {
  std::unique_ptr<CascadeStack> stack;
  std::vector<std::uint32_t> allSlots;  // every atlas slot: a new GiSystem uploads them all once
};
StreamedStack streamStack(const PackTileStore& store, TileLoader& loader, const BenchScene& scene,
                          int cascades);

}  // namespace sdfstream::bench
