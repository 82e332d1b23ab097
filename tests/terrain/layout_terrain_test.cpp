// Layout files with a terrain and instances: parsing, the sources they become, and errors that
// name the file and the key.
#include <filesystem>

#include <gtest/gtest.h>

#include "tests/gltf/gltf_test_util.h"
#include "tests/support/test_data.h"
#include "tests/terrain/png_writer.h"
#include "world/layout_sources.h"
#include "world/scene_layout.h"

namespace sdfstream {
namespace {

namespace fs = std::filesystem;
using Kind = InputErrorKind;

const fs::path kBox = test::assimpModels() / "glTF2/BoxTextured-glTF-Binary/BoxTextured.glb";

fs::path terrainDir(const std::string& name) {
  const fs::path dir = test::scratchDir(name);
  std::vector<std::uint16_t> v(16 * 16);
  for (int i = 0; i < 256; ++i) v[std::size_t(i)] = std::uint16_t(i);
  test::writeGrayPng(dir / "h.png", 16, 16, v, 8);
  return dir;
}

const char* kLayout = R"({
  "comment": "terrain and two instance sets",
  "terrain": {"heightmap": "h.png", "metresPerPixel": 5, "heightScale": 120,
              "origin": [-40, -10, -40], "albedo": [0.1, 0.3, 0.1]},
  "instances": [
    {"file": "BOX", "fitSize": 2, "onGround": true,
     "placements": [{"translation": [1, 2, 3]}, {"translation": [10, 0, 0], "scale": 2},
                    {"translation": [0, 0, 10], "rotation": [0, 0.7071068, 0, 0.7071068]}]},
    {"file": "BOX", "placements": [{"translation": [5, 5, 5]}]}
  ],
  "assets": [{"file": "BOX", "translation": [-5, 0, 0]}]
})";

std::string withBox(std::string s) {
  for (std::size_t at; (at = s.find("BOX")) != std::string::npos;) s.replace(at, 3, kBox.string());
  return s;
}

TEST(LayoutTerrain, ParsesTerrainAndInstances) {
  const fs::path dir = terrainDir("layout-terrain");
  test::writeText(dir / "world.json", withBox(kLayout));
  const ParsedLayout layout = parseLayout(dir / "world.json");
  ASSERT_TRUE(layout.terrain.has_value());
  EXPECT_EQ(layout.terrain->png, dir / "h.png");
  EXPECT_EQ(layout.terrain->metresPerPixel, 5.0);
  EXPECT_EQ(layout.terrain->heightScale, 120.0);
  EXPECT_EQ(layout.terrain->origin, glm::dvec3(-40, -10, -40));
  EXPECT_NEAR(layout.terrain->albedo.g, 0.3f, 1e-6f);
  ASSERT_EQ(layout.assets.size(), 3u);  // "assets" entries first, then "instances"
  EXPECT_EQ(layout.assets[0].key, "assets[0]");
  EXPECT_EQ(layout.assets[1].key, "instances[0]");
  ASSERT_EQ(layout.assets[1].placements.size(), 3u);
  EXPECT_EQ(layout.assets[1].placements[1].scale, glm::dvec3(2.0));
  EXPECT_EQ(*layout.assets[1].fitSize, 2.0);
  EXPECT_TRUE(layout.assets[1].onGround);
  EXPECT_EQ(layout.assets[2].placements.size(), 1u);

  // The placement transform puts an onGround asset's lowest point at the translation's height.
  const TriangleScene box = loadLayoutAsset(layout, layout.assets[1]);
  TriangleScene placed;
  appendTransformed(placed, box,
                    placementTransform(layout.assets[1], layout.assets[1].placements[0], box));
  EXPECT_NEAR(placed.boundsMin().y, 2.0, 1e-5);
  const glm::vec3 size = placed.boundsMax() - placed.boundsMin();
  EXPECT_NEAR(std::max({size.x, size.y, size.z}), 2.0, 1e-5);
}

TEST(LayoutTerrain, SingleSceneLoaderExpandsInstancesAndRefusesTerrain) {
  const fs::path dir = terrainDir("layout-instances");
  std::string noTerrain = R"({"instances": [{"file": "BOX", "placements": [
      {"translation": [0, 0, 0]}, {"translation": [3, 0, 0]}, {"translation": [6, 0, 0]}]}]})";
  test::writeText(dir / "inst.json", withBox(noTerrain));
  const TriangleScene scene = loadLayout(dir / "inst.json");
  test::writeText(dir / "one.json", withBox(R"({"assets": [{"file": "BOX"}]})"));
  const TriangleScene one = loadLayout(dir / "one.json");
  EXPECT_EQ(scene.triangles.size(), 3 * one.triangles.size());
  EXPECT_NEAR(scene.boundsMax().x - one.boundsMax().x, 6.0, 1e-5);

  test::writeText(dir / "terrain.json", withBox(kLayout));
  const std::string msg =
      test::expectInputError([&] { loadLayout(dir / "terrain.json"); }, Kind::Malformed);
  EXPECT_NE(msg.find("terrain"), std::string::npos) << msg;
}

TEST(LayoutTerrain, SourcesOnePerPlacementPlusTerrain) {
  const fs::path dir = terrainDir("layout-sources");
  test::writeText(dir / "world.json", withBox(kLayout));
  const auto sources = loadLayoutSources(dir / "world.json");
  ASSERT_EQ(sources.size(), 1u + 1u + 3u + 1u);  // terrain, assets[0], 3 + 1 placements
  // The terrain comes first and spans the heightmap: 15 px × 5 m from the origin.
  EXPECT_NEAR(sources[0]->boundsMin().x, -40.0, 1e-9);
  EXPECT_NEAR(sources[0]->boundsMax().z, -40.0 + 75.0, 1e-9);
  EXPECT_NEAR(sources[0]->boundsMax().y, -10.0 + 255.0 / 255.0 * 120.0, 1e-4);

  test::writeText(dir / "terrain-only.json",
                  R"({"terrain": {"heightmap": "h.png", "metresPerPixel": 1, "heightScale": 1}})");
  EXPECT_EQ(loadLayoutSources(dir / "terrain-only.json").size(), 1u);
  test::writeText(dir / "nothing.json", R"({"instances": []})");
  test::expectInputError([&] { loadLayoutSources(dir / "nothing.json"); }, Kind::Empty);
}

TEST(LayoutTerrain, ErrorsNameFileAndKey) {
  const fs::path dir = terrainDir("layout-terrain-bad");
  auto check = [&](const std::string& json, Kind kind, const std::string& mention) {
    test::writeText(dir / "bad.json", withBox(json));
    const std::string msg =
        test::expectInputError([&] { loadLayoutSources(dir / "bad.json"); }, kind);
    EXPECT_NE(msg.find("bad.json"), std::string::npos) << msg;
    EXPECT_NE(msg.find(mention), std::string::npos) << msg;
  };
  check(R"({"terrain": {"heightmap": "h.png", "heightScale": 1}})", Kind::Malformed,
        "terrain.metresPerPixel: required");
  check(R"({"terrain": {"heightmap": "h.png", "metresPerPixel": -1, "heightScale": 1}})",
        Kind::Malformed, "terrain.metresPerPixel");
  check(R"({"terrain": {"heightmap": "h.png", "metresPerPixel": 1, "heightScale": "x"}})",
        Kind::Malformed, "terrain.heightScale: expected a number");
  check(R"({"terrain": {"heightmap": "none.png", "metresPerPixel": 1, "heightScale": 1}})",
        Kind::MissingData, "terrain.heightmap");
  check(R"({"terrain": {"heightmap": "h.png", "metresPerPixel": 1, "heightScale": 1,
            "orgin": [0, 0, 0]}})",
        Kind::Malformed, "terrain.orgin: unknown key");
  check(R"({"terrain": {"heightmap": "h.png", "metresPerPixel": 1, "heightScale": 1,
            "origin": [0, 0]}})",
        Kind::Malformed, "terrain.origin: expected 3 numbers");
  check(R"({"instances": [{"file": "BOX"}]})", Kind::Malformed, "instances[0].placements");
  check(R"({"instances": [{"file": "BOX", "placements": [{}, {"translation": [1]}]}]})",
        Kind::Malformed, "instances[0].placements[1].translation: expected 3 numbers");
  check(R"({"instances": [{"file": "BOX", "placements": [{"fitSize": 2}]}]})", Kind::Malformed,
        "instances[0].placements[0].fitSize: unknown key");
  check(R"({"instances": [{"file": "nope.glb", "placements": []}]})", Kind::MissingData,
        "instances[0].file");
  check("{\n \"terrain\": {\"heightmap\": \"h.png\",,}\n}", Kind::Malformed, "line 2, column");
  // A heightmap that is not an image keeps its kind and names both files.
  test::writeText(dir / "fake.png", "not a png");
  check(R"({"terrain": {"heightmap": "fake.png", "metresPerPixel": 1, "heightScale": 1}})",
        Kind::Malformed, "fake.png");
}

}  // namespace
}  // namespace sdfstream
