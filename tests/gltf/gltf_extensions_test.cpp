// glTF features beyond the core that real files use: sparse accessors, quantized attributes,
// a second UV set, KHR_texture_transform, KHR_lights_punctual, and the refusal of any other
// required extension.
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "tests/gltf/gltf_test_util.h"
#include "tests/support/test_data.h"
#include "world/gltf_import.h"

namespace sdfstream {
namespace {

namespace fs = std::filesystem;
using test::expectInputError;
using Kind = InputErrorKind;

constexpr double kPi = 3.14159265358979323846;

// Appends raw bytes to buffer 0 of `j` (file <name>.bin in dir) and returns their byte offset.
std::size_t appendBytes(const fs::path& dir, const std::string& name, nlohmann::json& j,
                        const void* data, std::size_t size) {
  const fs::path bin = dir / (name + ".bin");
  const std::size_t offset = fs::file_size(bin);
  std::ofstream(bin, std::ios::binary | std::ios::app)
      .write(static_cast<const char*>(data), std::streamsize(size));
  j["buffers"][0]["byteLength"] = offset + size;
  return offset;
}

nlohmann::json oneTriangleMesh(nlohmann::json j) {
  j["meshes"] = {{{"primitives", {{{"attributes", {{"POSITION", 0}}}}}}}};
  j["nodes"] = {{{"mesh", 0}}};
  return j;
}

TEST(GltfSparse, ValuesReplaceTheBaseElementsTheyName) {
  const fs::path dir = test::scratchDir("gltf-sparse");
  nlohmann::json j =
      oneTriangleMesh(test::gltfWithPositions(dir, "tri", {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}));
  const std::uint8_t index[4] = {1, 0, 0, 0};  // padded to 4 bytes
  const float value[3] = {5.0f, 6.0f, 7.0f};
  const std::size_t indexAt = appendBytes(dir, "tri", j, index, sizeof index);
  const std::size_t valueAt = appendBytes(dir, "tri", j, value, sizeof value);
  j["bufferViews"].push_back({{"buffer", 0}, {"byteOffset", indexAt}, {"byteLength", 1}});
  j["bufferViews"].push_back({{"buffer", 0}, {"byteOffset", valueAt}, {"byteLength", 12}});
  j["accessors"][0]["sparse"] = {{"count", 1},
                                 {"indices", {{"bufferView", 1}, {"componentType", 5121}}},
                                 {"values", {{"bufferView", 2}}}};
  const TriangleScene scene = loadGltf(test::save(dir, "tri", j));
  ASSERT_EQ(scene.positions.size(), 3u);
  EXPECT_EQ(scene.positions[0], glm::vec3(0, 0, 0));
  EXPECT_EQ(scene.positions[1], glm::vec3(5, 6, 7));
  EXPECT_EQ(scene.positions[2], glm::vec3(0, 1, 0));
}

TEST(GltfSparse, WithoutABufferViewTheBaseIsZeros) {
  const fs::path dir = test::scratchDir("gltf-sparse-zero");
  // Buffer 0 holds the two substituted positions; the accessor itself has no bufferView.
  nlohmann::json j = oneTriangleMesh(test::gltfWithPositions(dir, "tri", {{1, 0, 0}, {0, 1, 0}}));
  const std::uint16_t index[2] = {1, 2};
  const std::size_t indexAt = appendBytes(dir, "tri", j, index, sizeof index);
  j["bufferViews"].push_back({{"buffer", 0}, {"byteOffset", indexAt}, {"byteLength", 4}});
  j["accessors"][0] = {{"componentType", 5126},
                       {"count", 3},
                       {"type", "VEC3"},
                       {"sparse",
                        {{"count", 2},
                         {"indices", {{"bufferView", 1}, {"componentType", 5123}}},
                         {"values", {{"bufferView", 0}}}}}};
  const TriangleScene scene = loadGltf(test::save(dir, "tri", j));
  ASSERT_EQ(scene.positions.size(), 3u);
  EXPECT_EQ(scene.positions[0], glm::vec3(0, 0, 0));
  EXPECT_EQ(scene.positions[1], glm::vec3(1, 0, 0));
  EXPECT_EQ(scene.positions[2], glm::vec3(0, 1, 0));
}

TEST(GltfSparse, IndexBeyondTheCountIsOutOfRange) {
  const fs::path dir = test::scratchDir("gltf-sparse-range");
  nlohmann::json j =
      oneTriangleMesh(test::gltfWithPositions(dir, "tri", {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}));
  const std::uint8_t index[4] = {9, 0, 0, 0};
  const std::size_t indexAt = appendBytes(dir, "tri", j, index, sizeof index);
  j["bufferViews"].push_back({{"buffer", 0}, {"byteOffset", indexAt}, {"byteLength", 1}});
  j["accessors"][0]["sparse"] = {{"count", 1},
                                 {"indices", {{"bufferView", 1}, {"componentType", 5121}}},
                                 {"values", {{"bufferView", 0}}}};
  const std::string msg =
      expectInputError([&] { loadGltf(test::save(dir, "tri", j)); }, Kind::OutOfRange);
  EXPECT_NE(msg.find("sparse index 9"), std::string::npos) << msg;
}

TEST(GltfSparse, HugeCountWithoutDataIsRefusedBeforeAllocating) {
  const fs::path dir = test::scratchDir("gltf-sparse-huge");
  nlohmann::json j = oneTriangleMesh(test::gltfWithPositions(dir, "tri", {{1, 0, 0}}));
  j["accessors"][0] = {{"componentType", 5126},
                       {"count", 2000000000},
                       {"type", "VEC3"},
                       {"sparse",
                        {{"count", 1},
                         {"indices", {{"bufferView", 0}, {"componentType", 5121}}},
                         {"values", {{"bufferView", 0}}}}}};
  expectInputError([&] { loadGltf(test::save(dir, "tri", j)); }, Kind::TooLarge);
}

// KHR_mesh_quantization: signed-byte normalized positions (value / 127) under a node scale.
TEST(GltfQuantization, NormalizedBytePositionsAreDequantizedByTheNode) {
  const fs::path dir = test::scratchDir("gltf-quant");
  nlohmann::json j = oneTriangleMesh(test::gltfWithPositions(dir, "tri", {}));
  const std::int8_t p[12] = {0, 0, 0, 0, 127, 0, 0, 0, 0, 127, 0, 0};  // stride 4
  const std::size_t at = appendBytes(dir, "tri", j, p, sizeof p);
  j["bufferViews"][0] = {{"buffer", 0}, {"byteOffset", at}, {"byteLength", 12}, {"byteStride", 4}};
  j["accessors"][0] = {{"bufferView", 0}, {"componentType", 5120}, {"normalized", true},
                       {"count", 3},      {"type", "VEC3"}};
  j["nodes"][0]["scale"] = {2.0, 2.0, 2.0};
  j["extensionsUsed"] = {"KHR_mesh_quantization"};
  j["extensionsRequired"] = {"KHR_mesh_quantization"};
  const TriangleScene scene = loadGltf(test::save(dir, "tri", j));
  ASSERT_EQ(scene.positions.size(), 3u);
  EXPECT_EQ(scene.positions[1], glm::vec3(2, 0, 0));
  EXPECT_EQ(scene.positions[2], glm::vec3(0, 2, 0));
}

TEST(GltfQuantization, ThirtyTwoBitIntegerPositionsAreRefused) {
  const fs::path dir = test::scratchDir("gltf-quant-u32");
  nlohmann::json j = oneTriangleMesh(test::gltfWithPositions(dir, "tri", {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}));
  j["accessors"][0]["componentType"] = 5125;
  const std::string msg =
      expectInputError([&] { loadGltf(test::save(dir, "tri", j)); }, Kind::Malformed);
  EXPECT_NE(msg.find("POSITION"), std::string::npos) << msg;
}

TEST(GltfExtensions, AnUnsupportedRequiredExtensionIsRefusedByName) {
  const fs::path dir = test::scratchDir("gltf-required");
  nlohmann::json j =
      oneTriangleMesh(test::gltfWithPositions(dir, "tri", {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}));
  j["extensionsUsed"] = {"KHR_mesh_quantization", "KHR_draco_mesh_compression"};
  j["extensionsRequired"] = {"KHR_mesh_quantization", "KHR_draco_mesh_compression"};
  const std::string msg =
      expectInputError([&] { loadGltf(test::save(dir, "tri", j)); }, Kind::Unsupported);
  EXPECT_NE(msg.find("KHR_draco_mesh_compression"), std::string::npos) << msg;
  EXPECT_NE(msg.find("tri.gltf"), std::string::npos) << msg;
  // Merely used, not required: imported.
  j["extensionsRequired"] = {"KHR_mesh_quantization"};
  EXPECT_EQ(loadGltf(test::save(dir, "tri", j)).triangles.size(), 1u);
}

// The extension's own example: offset [0, 1], rotation pi/2, scale 0.5 uses the image's lower
// left quadrant, so the unit square's corners land on [0, 0.5] x [0.5, 1].
TEST(GltfTextureTransform, TheSpecExampleSelectsTheLowerLeftQuadrant) {
  const fs::path src = test::assimpModels() / "glTF2" / "BoxTextured-glTF";
  const fs::path dir = test::scratchDir("gltf-transform");
  for (const char* f : {"BoxTextured0.bin", "CesiumLogoFlat.png"})
    fs::copy_file(src / f, dir / f);
  std::ifstream in(src / "BoxTextured.gltf");
  nlohmann::json j = nlohmann::json::parse(in);
  j["materials"][0]["pbrMetallicRoughness"]["baseColorTexture"]["extensions"] = {
      {"KHR_texture_transform",
       {{"offset", {0.0, 1.0}}, {"rotation", kPi / 2}, {"scale", {0.5, 0.5}}}}};
  const TriangleScene moved = loadGltf(test::save(dir, "moved", j));
  const UvTransform& t = moved.materials[0].baseColorUv;
  auto near = [](glm::vec2 a, glm::vec2 b) { return glm::length(a - b) < 1e-6f; };
  EXPECT_TRUE(near(t.apply({0, 0}), {0.0f, 1.0f}));
  EXPECT_TRUE(near(t.apply({1, 0}), {0.0f, 0.5f}));
  EXPECT_TRUE(near(t.apply({0, 1}), {0.5f, 1.0f}));
  EXPECT_TRUE(near(t.apply({1, 1}), {0.5f, 0.5f}));
  // The albedo follows: the transformed scene samples what the plain one does at t(uv).
  const TriangleScene plain = loadGltf(src / "BoxTextured.gltf");
  TriangleScene expected = plain;
  expected.materials[0].baseColorUv = t;
  int differs = 0;
  for (std::uint32_t tri = 0; tri < plain.triangles.size(); ++tri) {
    const glm::vec2 bary(0.3f, 0.2f);
    const glm::vec4 a = sampleAlbedo(moved, tri, bary), e = sampleAlbedo(expected, tri, bary);
    EXPECT_LT(glm::length(a - e), 1e-6f) << tri;
    differs += glm::length(a - sampleAlbedo(plain, tri, bary)) > 1e-3f;
  }
  EXPECT_GT(differs, 0) << "the transform changed no sample: the test cannot tell";
}

// A material reading TEXCOORD_1: with TEXCOORD_0 absent, only the second set carries the UVs.
TEST(GltfUvSets, AMaterialReadsTheSetItNames) {
  const fs::path src = test::assimpModels() / "glTF2" / "BoxTextured-glTF";
  const fs::path dir = test::scratchDir("gltf-uv1");
  for (const char* f : {"BoxTextured0.bin", "CesiumLogoFlat.png"})
    fs::copy_file(src / f, dir / f);
  std::ifstream in(src / "BoxTextured.gltf");
  nlohmann::json j = nlohmann::json::parse(in);
  auto& attributes = j["meshes"][0]["primitives"][0]["attributes"];
  attributes["TEXCOORD_1"] = attributes["TEXCOORD_0"];
  attributes.erase("TEXCOORD_0");
  j["materials"][0]["pbrMetallicRoughness"]["baseColorTexture"]["texCoord"] = 1;
  const TriangleScene second = loadGltf(test::save(dir, "second", j));
  const TriangleScene plain = loadGltf(src / "BoxTextured.gltf");
  ASSERT_EQ(second.uvs1.size(), second.positions.size());
  EXPECT_EQ(second.uvs1, plain.uvs);
  EXPECT_EQ(second.uvs, std::vector<glm::vec2>(second.positions.size(), glm::vec2(0.0f)));
  for (std::uint32_t tri = 0; tri < plain.triangles.size(); ++tri)
    EXPECT_EQ(sampleAlbedo(second, tri, {0.3f, 0.2f}), sampleAlbedo(plain, tri, {0.3f, 0.2f}));
}

TEST(GltfLights, PunctualLightsArePlacedByTheirNodes) {
  const fs::path dir = test::scratchDir("gltf-lights");
  nlohmann::json j =
      oneTriangleMesh(test::gltfWithPositions(dir, "tri", {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}));
  j["extensionsUsed"] = {"KHR_lights_punctual"};
  j["extensions"]["KHR_lights_punctual"]["lights"] = {
      {{"type", "point"}, {"color", {1.0, 0.5, 0.25}}, {"intensity", 40.0}, {"range", 12.0}},
      {{"type", "spot"}, {"intensity", 100.0}, {"spot", {{"innerConeAngle", 0.2}, {"outerConeAngle", 0.5}}}},
      {{"type", "directional"}, {"intensity", 3.0}}};
  // Node 1: the point light at (1, 2, 3). Node 3: the spot, turned -90° about +X so -Z points
  // down -Y, under a parent translated to (0, 5, 0). Node 4: the sun, turned 90° about +Y so it
  // shines along -X.
  const double h = std::sqrt(0.5);
  j["nodes"].push_back({{"translation", {1, 2, 3}}, {"extensions", {{"KHR_lights_punctual", {{"light", 0}}}}}});
  j["nodes"].push_back({{"translation", {0, 5, 0}}, {"children", {3}}});
  j["nodes"].push_back({{"rotation", {-h, 0, 0, h}}, {"extensions", {{"KHR_lights_punctual", {{"light", 1}}}}}});
  j["nodes"].push_back({{"rotation", {0, h, 0, h}}, {"extensions", {{"KHR_lights_punctual", {{"light", 2}}}}}});
  j["scenes"] = {{{"nodes", {0, 1, 2, 4}}}};
  const TriangleScene scene = loadGltf(test::save(dir, "lit", j));
  ASSERT_EQ(scene.lights.size(), 3u);
  const SceneLight& point = scene.lights[0];
  EXPECT_EQ(point.type, SceneLight::Type::Point);
  EXPECT_NEAR(glm::length(point.position - glm::dvec3(1, 2, 3)), 0.0, 1e-9);
  EXPECT_EQ(point.color, glm::vec3(1.0f, 0.5f, 0.25f));
  EXPECT_FLOAT_EQ(point.intensity, 40.0f);
  EXPECT_FLOAT_EQ(point.range, 12.0f);
  const SceneLight& spot = scene.lights[1];
  EXPECT_EQ(spot.type, SceneLight::Type::Spot);
  EXPECT_NEAR(glm::length(spot.position - glm::dvec3(0, 5, 0)), 0.0, 1e-9);
  EXPECT_NEAR(glm::length(spot.direction - glm::vec3(0, -1, 0)), 0.0f, 1e-6f);
  EXPECT_NEAR(spot.innerConeDegrees, 0.2 * 180 / kPi, 1e-4);
  EXPECT_NEAR(spot.outerConeDegrees, 0.5 * 180 / kPi, 1e-4);
  const SceneLight& sun = scene.lights[2];
  EXPECT_EQ(sun.type, SceneLight::Type::Sun);
  EXPECT_NEAR(glm::length(sun.direction - glm::vec3(-1, 0, 0)), 0.0f, 1e-6f);
  EXPECT_FLOAT_EQ(sun.intensity, 3.0f);
}

TEST(GltfLights, BadDefinitionsAndReferencesFailClearly) {
  const fs::path dir = test::scratchDir("gltf-lights-bad");
  nlohmann::json j =
      oneTriangleMesh(test::gltfWithPositions(dir, "tri", {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}));
  j["extensions"]["KHR_lights_punctual"]["lights"] = {{{"type", "area"}}};
  std::string msg = expectInputError([&] { loadGltf(test::save(dir, "t", j)); }, Kind::Malformed);
  EXPECT_NE(msg.find("lights[0].type"), std::string::npos) << msg;
  j["extensions"]["KHR_lights_punctual"]["lights"] = {{{"type", "point"}, {"intensity", -1.0}}};
  expectInputError([&] { loadGltf(test::save(dir, "t", j)); }, Kind::Malformed);
  j["extensions"]["KHR_lights_punctual"]["lights"] = {
      {{"type", "spot"}, {"spot", {{"innerConeAngle", 0.6}, {"outerConeAngle", 0.5}}}}};
  expectInputError([&] { loadGltf(test::save(dir, "t", j)); }, Kind::Malformed);
  j["extensions"]["KHR_lights_punctual"]["lights"] = {{{"type", "point"}}};
  j["nodes"][0]["extensions"] = {{"KHR_lights_punctual", {{"light", 3}}}};
  msg = expectInputError([&] { loadGltf(test::save(dir, "t", j)); }, Kind::OutOfRange);
  EXPECT_NE(msg.find("light 3"), std::string::npos) << msg;
}

}  // namespace
}  // namespace sdfstream
