// The whole streamed path on a real pack, shared by the trace and probe tests: Debian's glmark2
// bunny OBJ → 3-LOD pack (v0 = 1.2 cm, so cascade 0 spans 1.5 m and rays cross cascades) →
// PackTileStore → TileLoader → a 3-cascade CascadeStack settled around a camera in front of it.
#pragma once

#include <filesystem>
#include <memory>
#include <string>

#include <gtest/gtest.h>

#include "streaming/cascade_stack.h"
#include "streaming/pack_store.h"
#include "streaming/tile_loader.h"
#include "tests/support/test_data.h"
#include "world/obj_import.h"
#include "world/pack_import.h"
#include "world/scene_lights.h"

namespace sdfstream::test {

struct StreamedBunny {
  TriangleScene triangles;  // the source mesh, for reference checks
  std::filesystem::path pack;
  std::unique_ptr<PackTileStore> store;
  std::unique_ptr<TileLoader> loader;
  std::unique_ptr<CascadeStack> stack;
  glm::dvec3 camera;
};

inline StreamedBunny streamBunny(const std::string& scratchName = "streamed-bunny") {
  StreamedBunny b;
  const std::filesystem::path obj = "/usr/share/glmark2/models/bunny.obj";
  b.triangles = loadObj(obj);
  b.pack = scratchDir(scratchName) / "pack";
  PackImportOptions o;
  o.voxelSize = 0.012;
  o.lodCount = 3;
  o.tileVoxels = 64;
  auto sources = sourcesForInput(obj, 0.0, o.limits);
  PartitionSpec spec = partitionFor(sources, o, "bunny.obj");
  importPack(sources, b.pack, spec, o, "bunny.obj");
  b.store = std::make_unique<PackTileStore>(b.pack);
  b.loader = std::make_unique<TileLoader>(*b.store);
  StreamingOptions so;
  so.cascades = 3;
  b.stack = std::make_unique<CascadeStack>(*b.store, *b.loader, so);
  b.camera = glm::dvec3(0.3, 0.4, 1.4);  // in front of the bunny, outside it
  for (int i = 0; i < 100 && !b.stack->settled(); ++i) {
    b.stack->update(b.camera);
    b.loader->waitIdle();
  }
  EXPECT_TRUE(b.stack->settled());
  return b;
}

// The streamed bunny's lights in the GI tests: a sun from above and a blue sky.
inline SceneLights bunnySunAndSky() {
  SceneLights lights;
  SceneLight sun;
  sun.direction = glm::normalize(glm::vec3(0.3f, -1.0f, 0.2f));
  sun.intensity = 3.0f;
  lights.lights.push_back(sun);
  lights.sky.zenith = glm::vec3(0.2f, 0.3f, 0.5f);
  return lights;
}

}  // namespace sdfstream::test
