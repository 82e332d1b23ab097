// Layout files: assets placed by TRS / fitSize / onGround, boxes, and errors that name the key.
#include <filesystem>

#include <gtest/gtest.h>

#include "tests/gltf/gltf_test_util.h"
#include "tests/support/test_data.h"
#include "world/scene_layout.h"

namespace sdfstream {
namespace {

namespace fs = std::filesystem;
using Kind = InputErrorKind;

void expectNear(glm::vec3 a, glm::vec3 b, float eps = 1e-5f) {
  EXPECT_NEAR(a.x, b.x, eps);
  EXPECT_NEAR(a.y, b.y, eps);
  EXPECT_NEAR(a.z, b.z, eps);
}

const fs::path kBox = test::assimpModels() / "glTF2/BoxTextured-glTF-Binary/BoxTextured.glb";

// A layout directory with assets/tri.gltf: one triangle (0,0,0) (1,0,0) (0,1,0).
fs::path layoutDir(const std::string& name) {
  const fs::path dir = test::scratchDir(name);
  fs::create_directories(dir / "assets");
  nlohmann::json j =
      test::gltfWithPositions(dir / "assets", "tri", {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}});
  j["meshes"] = {{{"primitives", {{{"attributes", {{"POSITION", 0}}}}}}}};
  j["nodes"] = {{{"mesh", 0}}};
  test::save(dir / "assets", "tri", j);
  return dir;
}

TEST(SceneLayout, TwoAssetsAndABox) {
  const fs::path dir = layoutDir("layout-ok");
  nlohmann::json layout;
  layout["assets"] = {
      {{"file", kBox.string()}, {"fitSize", 3.0}, {"onGround", true}, {"translation", {5, 0, 0}}},
      {{"file", "assets/tri.gltf"},
       {"translation", {10, 0, 0}},
       {"rotation", {0, 0, std::sqrt(0.5), std::sqrt(0.5)}},  // 90° about z
       {"scale", 2}}};
  layout["boxes"] = {{{"min", {-4, -0.5, -4}},
                      {"max", {4, 0, 4}},
                      {"albedo", {0.5, 0.4, 0.3}},
                      {"emission", {0, 0, 3}}}};
  test::writeText(dir / "layout.json", layout.dump());
  const TriangleScene scene = loadLayout(dir / "layout.json");
  ASSERT_EQ(scene.triangles.size(), 12u + 1u + 12u);
  ASSERT_EQ(scene.triangleMaterial.size(), scene.triangles.size());
  ASSERT_EQ(scene.uvs.size(), scene.positions.size());

  // The unit box, fitted to 3 m, resting on y = 0, moved to x = 5.
  TriangleScene box;
  box.positions.assign(scene.positions.begin(), scene.positions.begin() + 24);
  expectNear(box.boundsMin(), {3.5f, 0.0f, -1.5f});
  expectNear(box.boundsMax(), {6.5f, 3.0f, 1.5f});
  EXPECT_EQ(scene.materials[0].baseColorTexture, 0);

  // The triangle: scaled 2, rotated 90° about z, moved to x = 10.
  const glm::uvec3 t = scene.triangles[12];
  expectNear(scene.positions[t.x], {10, 0, 0});
  expectNear(scene.positions[t.y], {10, 2, 0});
  expectNear(scene.positions[t.z], {8, 0, 0});
  EXPECT_EQ(scene.materials[scene.triangleMaterial[12]].name, "default");

  // The slab: closed, outward facing, its own material.
  double area = 0.0;
  for (std::size_t i = 13; i < 25; ++i) {
    const glm::uvec3 f = scene.triangles[i];
    const glm::vec3 a = scene.positions[f.x], b = scene.positions[f.y], c = scene.positions[f.z];
    const glm::vec3 n = glm::cross(b - a, c - a);
    area += 0.5 * glm::length(n);
    EXPECT_GT(glm::dot(n, (a + b + c) / 3.0f - glm::vec3(0, -0.25f, 0)), 0.0f) << "inward face";
  }
  EXPECT_NEAR(area, 2 * 64 + 4 * 8 * 0.5, 1e-4);
  const glm::vec4 albedo = sampleAlbedo(scene, 13, {0.2f, 0.2f});
  expectNear(glm::vec3(albedo), {0.5f, 0.4f, 0.3f});
  expectNear(sampleEmission(scene, 24, {0.2f, 0.2f}), {0, 0, 3});
}

TEST(SceneLayout, ErrorsNameFileAndKey) {
  const fs::path dir = layoutDir("layout-bad");
  auto check = [&](const std::string& json, Kind kind, const std::string& mention) {
    test::writeText(dir / "layout.json", json);
    const std::string msg = test::expectInputError([&] { loadLayout(dir / "layout.json"); }, kind);
    EXPECT_NE(msg.find("layout.json"), std::string::npos) << msg;
    EXPECT_NE(msg.find(mention), std::string::npos) << msg;
  };
  check(R"({"assets":[{"file":"assets/tri.gltf"},{"file":"assets/tri.gltf","translation":[1,2]}]})",
        Kind::Malformed, "assets[1].translation: expected 3 numbers");
  check(R"({"assets":[{"file":"assets/tri.gltf","rotaton":[0,0,0,1]}]})", Kind::Malformed,
        "assets[0].rotaton: unknown key");
  check(R"({"boxes":[{"min":[0,0,0],"max":[1,1,"a"]}]})", Kind::Malformed,
        "boxes[0].max: expected 3 numbers");
  check("{\n  \"assets\": [\n    {\"file\": }\n  ]\n}", Kind::Malformed, "line 3, column 14");
  check(R"({"assets":[{"file":"assets/none.glb"}]})", Kind::MissingData, "assets[0].file");
  check(R"({"assets":[]})", Kind::Empty, "no assets");
  // An asset's own failure keeps its kind and names both files.
  const fs::path bad = test::assimpModels() / "glTF2/IndexOutOfRange/IndexOutOfRange.gltf";
  check(R"({"assets":[{"file":")" + bad.string() + R"("}]})", Kind::OutOfRange,
        "IndexOutOfRange.gltf");
  const std::string msg =
      test::expectInputError([&] { loadLayout(dir / "missing.json"); }, Kind::Io);
  EXPECT_NE(msg.find("missing.json"), std::string::npos) << msg;
}

}  // namespace
}  // namespace sdfstream
