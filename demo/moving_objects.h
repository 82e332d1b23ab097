// Scripted moving objects for the demo commands (the fly-through shows moving objects casting
// indirect shadows): boxes and spheres placed deterministically from a seed,
// each bound to a ScriptedMotion mover (objects/scripted_motion.h), so any frame can be replayed
// alone. `sdfstream fly` spreads them along its camera path on the pack's ground; `sdfstream demo`
// adds a few to its built-in scene. Not thread-safe (one owner, the frame loop).
#pragma once

#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <utility>
#include <vector>

#include <glm/glm.hpp>

#include "demo/fly_path.h"
#include "objects/instance_set.h"
#include "objects/object_library.h"
#include "objects/scripted_motion.h"
#include "streaming/tile_store.h"

namespace sdfstream {

// The meshes, their instances and the motion that drives them. Renderers keep pointers to
// library and instances (GiRenderer::setObjects): hold it by unique_ptr so they never move.
struct DemoObjects {
  ObjectLibrary library;
  InstanceSet instances;
  ScriptedMotion motion;

  explicit DemoObjects(ObjectSdfSettings settings) : library(settings) {}
  DemoObjects(const DemoObjects&) = delete;
  DemoObjects& operator=(const DemoObjects&) = delete;
  // Moves every instance to its pose at `seconds` (a pure function of time).
  void apply(double seconds) { motion.apply(instances, seconds); }
};

// Object SDF grids of the demo objects: 16-24 samples across (boxes and spheres need no more;
// about 0.05 s per mesh to build, 12 bytes per sample).
inline constexpr ObjectSdfSettings kDemoObjectSdf{16, 24, 0.0, 2};

// Ground heights of a world pack, read from its LOD-0 tiles on the calling thread (the fly's
// tile loader is not involved). Each tile column is loaded once, on first use, turned into one
// height per LOD-0 sample line (4 bytes each: 256 KB for a 256-voxel tile) and dropped. Tiles
// that fail to load count as absent (no ground there), never as an error: the objects are
// decoration.
class PackGround {
 public:
  // yMin / yMax: the pack's world bounds in y (the tiles searched).
  PackGround(const TileStore& store, double yMin, double yMax);
  // World y of the highest surface on the vertical line through (x, z): the topmost LOD-0 sample
  // whose distance is <= 0, interpolated with the sample above it. nullopt where no LOD-0 brick
  // lies on that line (no surface, or outside the pack).
  std::optional<double> heightAt(double x, double z);

 private:
  // Heights (LOD-0 samples above the origin, NaN: none) of tile column (x, z), x fastest.
  const std::vector<float>& column(glm::ivec2 tile);

  const TileStore& store_;
  int tileYMin_, tileYMax_;
  std::map<std::pair<int, int>, std::vector<float>> columns_;
};

struct FlyObjectsSettings {
  std::uint32_t count = 150;
  double sBegin = 0.0, sEnd = 0.0;      // stretch of the path (arc length, metres) they spread over
  double minSize = 1.0, maxSize = 4.0;  // longest edge / diameter, metres
  // Every largeEvery-th object is largeMin..largeMax metres instead: cascade 0's probes are 8 m
  // apart on a 1 m-voxel world, and irradiance probes blur anything smaller than their spacing,
  // so only objects larger than that darken the indirect light under them visibly (the small
  // ones cast direct shadows; their indirect shadows are a few percent).
  std::uint32_t largeEvery = 6;  // 0: none
  double largeMin = 8.0, largeMax = 14.0;
  double maxSide = 25.0;  // largest distance from the path, metres (horizontal)
  std::uint64_t seed = 7;
};

// Spreads settings.count objects along the path between sBegin and sEnd (stratified in arc
// length, alternating sides, 2 m .. maxSide off the path's horizontal line, so the camera
// flying the path sees them ahead and below; a few large, see largeEvery): boxes and spheres in
// four bright colours, a third
// each orbiting a hover point 0.5-3 m above the ground, falling onto the ground again and again,
// and driving a rectangular loop on it. Where the ground is unknown (no brick) an object moves
// closer to the path (half the side distance at a time, not nearer than 2 m) and is skipped if the
// ground stays unknown, so fewer objects may result. Instances start at their pose for t = 0.
std::unique_ptr<DemoObjects> flyObjects(PackGround& ground, const FlyPath& path,
                                        const FlyObjectsSettings& settings);

// A few objects for the built-in demo scene (demo/default_scene.json: ground top at y = 0,
// metres), all on the open front of its ground: a sphere circling 0.4 m above the ground, a cube
// that keeps dropping onto it and a flat box driving a loop. Slow enough that a still image after
// a few GI frames shows converged indirect shadows.
std::unique_ptr<DemoObjects> demoSceneObjects();

}  // namespace sdfstream
