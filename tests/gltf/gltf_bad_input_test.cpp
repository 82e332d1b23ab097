// Broken and hostile glTF inputs: each must fail with one line naming the file and the exact kind.
#include <filesystem>
#include <string>

#include <gtest/gtest.h>

#include "tests/gltf/gltf_test_util.h"
#include "tests/support/test_data.h"
#include "world/gltf_import.h"

namespace sdfstream {
namespace {

namespace fs = std::filesystem;
using test::expectInputError;
using Kind = InputErrorKind;

fs::path model(const std::string& relative) { return test::assimpModels() / "glTF2" / relative; }

struct BadFile {
  const char* path;
  Kind kind;
  const char* mentions;  // a word the message must contain
};

class GltfBadFile : public ::testing::TestWithParam<BadFile> {};

TEST_P(GltfBadFile, FailsWithItsKind) {
  const fs::path file = model(GetParam().path);
  ASSERT_TRUE(fs::exists(file)) << file;
  const std::string msg = expectInputError([&] { loadGltf(file); }, GetParam().kind);
  EXPECT_NE(msg.find(file.filename().string()), std::string::npos) << msg;
  EXPECT_NE(msg.find(GetParam().mentions), std::string::npos) << msg;
}

INSTANTIATE_TEST_SUITE_P(
    AssimpModels, GltfBadFile,
    ::testing::Values(
        BadFile{"MissingBin/BoxTextured.gltf", Kind::MissingData, "BoxTextured0.bin"},
        BadFile{"IndexOutOfRange/IndexOutOfRange.gltf", Kind::OutOfRange, "index"},
        BadFile{"IndexOutOfRange/AllIndicesOutOfRange.gltf", Kind::OutOfRange, "index"},
        BadFile{"BoxWithInfinites-glTF-Binary/BoxWithInfinites.glb", Kind::NonFinite, "vertex"},
        BadFile{"RecursiveNodes/RecursiveNodes.gltf", Kind::Malformed, "cycle"},
        BadFile{"wrongTypes/badArray.gltf", Kind::Malformed, "meshes[0].primitives"},
        BadFile{"wrongTypes/badExtension.gltf", Kind::Malformed, "extensions"},
        BadFile{"wrongTypes/badNumber.gltf", Kind::Malformed, "normalTexture.scale"},
        BadFile{"wrongTypes/badObject.gltf", Kind::Malformed, "pbrMetallicRoughness"},
        BadFile{"wrongTypes/badString.gltf", Kind::Malformed, "scenes[0].name"},
        BadFile{"wrongTypes/badUint.gltf", Kind::Malformed, "baseColorTexture.index"},
        BadFile{"TestNoRootNode/SceneWithoutNodes.gltf", Kind::Empty, "no triangles"},
        // "scene": 0 with no scenes array: a dangling index.
        BadFile{"TestNoRootNode/NoScene.gltf", Kind::OutOfRange, "scene 0"}));

TEST(GltfBadInput, MissingFileIsIo) {
  const fs::path file = test::scratchDir("gltf-missing") / "nothing.gltf";
  const std::string msg = expectInputError([&] { loadGltf(file); }, Kind::Io);
  EXPECT_NE(msg.find("nothing.gltf"), std::string::npos) << msg;
}

TEST(GltfBadInput, InvalidJsonNamesLineAndColumn) {
  const fs::path dir = test::scratchDir("gltf-badjson");
  test::writeText(dir / "bad.gltf", "{\n  \"asset\": {\"version\": \"2.0\"},\n  \"scenes\": [ }\n");
  const std::string msg = expectInputError([&] { loadGltf(dir / "bad.gltf"); }, Kind::Malformed);
  EXPECT_NE(msg.find("bad.gltf"), std::string::npos) << msg;
  EXPECT_NE(msg.find("line 3, column 15"), std::string::npos) << msg;
}

TEST(GltfBadInput, GlbCutInHalfIsTruncated) {
  const fs::path dir = test::scratchDir("gltf-truncated");
  const fs::path file = dir / "half.glb";
  fs::copy_file(model("BoxTextured-glTF-Binary/BoxTextured.glb"), file);
  fs::resize_file(file, fs::file_size(file) / 2);
  const std::string msg = expectInputError([&] { loadGltf(file); }, Kind::Truncated);
  EXPECT_NE(msg.find("half.glb"), std::string::npos) << msg;
  // Down to a few bytes: still Truncated, never a crash.
  for (std::uintmax_t size : {24u, 19u, 12u, 7u, 0u}) {  // shrinking: growing pads zeros
    fs::resize_file(file, size);
    expectInputError([&] { loadGltf(file); }, Kind::Truncated);
  }
}

TEST(GltfBadInput, BinShorterThanDeclaredIsTruncated) {
  const fs::path dir = test::scratchDir("gltf-shortbin");
  nlohmann::json j = test::gltfWithPositions(dir, "tri", {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}});
  j["buffers"][0]["byteLength"] = 72;  // the file holds 36
  j["meshes"] = {{{"primitives", {{{"attributes", {{"POSITION", 0}}}}}}}};
  j["nodes"] = {{{"mesh", 0}}};
  expectInputError([&] { loadGltf(test::save(dir, "tri", j)); }, Kind::Truncated);
}

TEST(GltfBadInput, BufferViewPastBufferIsTruncated) {
  const fs::path dir = test::scratchDir("gltf-shortview");
  nlohmann::json j = test::gltfWithPositions(dir, "tri", {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}});
  j["bufferViews"][0]["byteOffset"] = 12;  // 12 + 36 > 36
  j["meshes"] = {{{"primitives", {{{"attributes", {{"POSITION", 0}}}}}}}};
  j["nodes"] = {{{"mesh", 0}}};
  expectInputError([&] { loadGltf(test::save(dir, "tri", j)); }, Kind::Truncated);
}

TEST(GltfBadInput, AccessorPastBufferViewIsOutOfRange) {
  const fs::path dir = test::scratchDir("gltf-longaccessor");
  nlohmann::json j = test::gltfWithPositions(dir, "tri", {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}});
  j["accessors"][0]["byteOffset"] = 4;
  j["meshes"] = {{{"primitives", {{{"attributes", {{"POSITION", 0}}}}}}}};
  j["nodes"] = {{{"mesh", 0}}};
  expectInputError([&] { loadGltf(test::save(dir, "tri", j)); }, Kind::OutOfRange);
}

// Found by gltf_fuzz: nlohmann throws out_of_range, not parse_error, for a number beyond double.
TEST(GltfBadInput, NumberTooLargeForADoubleIsMalformed) {
  const fs::path dir = test::scratchDir("gltf-huge-number");
  test::writeText(dir / "huge.gltf", R"({"asset": {"version": "2.0"}, "scene": 1e999})");
  const std::string msg =
      expectInputError([&] { loadGltf(dir / "huge.gltf"); }, Kind::Malformed);
  EXPECT_NE(msg.find("huge.gltf"), std::string::npos) << msg;
  EXPECT_NE(msg.find("invalid JSON"), std::string::npos) << msg;
  // The minimized GLB the fuzzer wrote (tests/gltf/data/fuzz/): the same through the JSON chunk.
  const fs::path glb = test::sourceDir() / "tests/gltf/data/fuzz/number-overflow.glb";
  expectInputError([&] { loadGltf(glb); }, Kind::Malformed);
}

TEST(GltfBadInput, MissingImageIsMissingData) {
  const fs::path dir = test::scratchDir("gltf-noimage");
  const fs::path src = model("BoxTextured-glTF");
  fs::copy_file(src / "BoxTextured.gltf", dir / "BoxTextured.gltf");
  fs::copy_file(src / "BoxTextured0.bin", dir / "BoxTextured0.bin");
  const std::string msg =
      expectInputError([&] { loadGltf(dir / "BoxTextured.gltf"); }, Kind::MissingData);
  EXPECT_NE(msg.find("CesiumLogoFlat.png"), std::string::npos) << msg;
}

TEST(GltfBadInput, MeshIndexOutOfRange) {
  const fs::path dir = test::scratchDir("gltf-badmesh");
  nlohmann::json j = test::gltfWithPositions(dir, "tri", {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}});
  j["meshes"] = {{{"primitives", {{{"attributes", {{"POSITION", 0}}}}}}}};
  j["nodes"] = {{{"mesh", 3}}};
  expectInputError([&] { loadGltf(test::save(dir, "tri", j)); }, Kind::OutOfRange);
}

TEST(GltfBadInput, DeepChainDoesNotOverflowTheStack) {
  // 200k nested nodes: valid, so it must load (an importer recursing per node would crash).
  const fs::path dir = test::scratchDir("gltf-deep");
  nlohmann::json j = test::gltfWithPositions(dir, "tri", {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}});
  j["meshes"] = {{{"primitives", {{{"attributes", {{"POSITION", 0}}}}}}}};
  const int depth = 200000;
  nlohmann::json nodes = nlohmann::json::array();
  for (int i = 0; i < depth - 1; ++i) nodes.push_back({{"children", {i + 1}}});
  nodes.push_back({{"mesh", 0}, {"translation", {1, 0, 0}}});
  j["nodes"] = nodes;
  j["scenes"] = {{{"nodes", {0}}}};
  const TriangleScene scene = loadGltf(test::save(dir, "tri", j));
  EXPECT_EQ(scene.triangles.size(), 1u);
  EXPECT_EQ(scene.positions[0], glm::vec3(1, 0, 0));
}

}  // namespace
}  // namespace sdfstream
