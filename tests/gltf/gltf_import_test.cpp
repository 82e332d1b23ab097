// glTF import on real files and on small files written here with known answers.
#include <cmath>
#include <filesystem>

#include <gtest/gtest.h>
#include <stb_image.h>
#include <glm/gtc/matrix_inverse.hpp>

#include "tests/gltf/gltf_test_util.h"
#include "tests/support/test_data.h"
#include "world/gltf_import.h"

namespace sdfstream {
namespace {

namespace fs = std::filesystem;

fs::path model(const std::string& relative) { return test::assimpModels() / "glTF2" / relative; }

void expectNear(glm::vec3 a, glm::vec3 b, float eps = 1e-5f) {
  EXPECT_NEAR(a.x, b.x, eps);
  EXPECT_NEAR(a.y, b.y, eps);
  EXPECT_NEAR(a.z, b.z, eps);
}

float srgbToLinear(unsigned char c) {
  const double v = c / 255.0;
  return float(v <= 0.04045 ? v / 12.92 : std::pow((v + 0.055) / 1.055, 2.4));
}

TEST(GltfImport, BoxTexturedGeometryAndTexture) {
  const TriangleScene scene = loadGltf(model("BoxTextured-glTF/BoxTextured.gltf"));
  ASSERT_EQ(scene.triangles.size(), 12u);
  ASSERT_EQ(scene.triangleMaterial.size(), 12u);
  ASSERT_EQ(scene.uvs.size(), scene.positions.size());
  expectNear(scene.boundsMin(), glm::vec3(-0.5f));
  expectNear(scene.boundsMax(), glm::vec3(0.5f));
  EXPECT_NEAR(scene.surfaceArea(), 6.0, 1e-5);
  ASSERT_EQ(scene.materials.size(), 1u);
  const Material& m = scene.materials[0];
  ASSERT_EQ(m.baseColorTexture, 0);
  ASSERT_EQ(scene.textures.size(), 1u);

  // Decode the PNG independently and compare one texel, sampled at its exact centre.
  int w = 0, h = 0, comp = 0;
  const fs::path png = model("BoxTextured-glTF/CesiumLogoFlat.png");
  unsigned char* pixels = stbi_load(png.c_str(), &w, &h, &comp, 4);
  ASSERT_NE(pixels, nullptr);
  EXPECT_EQ(scene.textures[0].width, w);
  EXPECT_EQ(scene.textures[0].height, h);

  // Texel under the centroid of triangle 0, then barycentrics that land on its centre.
  const glm::uvec3 t = scene.triangles[0];
  const glm::vec2 uv0 = scene.uvs[t.x], e1 = scene.uvs[t.y] - uv0, e2 = scene.uvs[t.z] - uv0;
  const glm::vec2 centroid = uv0 + (e1 + e2) / 3.0f;
  const glm::ivec2 texel(glm::floor(centroid * glm::vec2(w, h)));
  const glm::vec2 target = (glm::vec2(texel) + 0.5f) / glm::vec2(w, h);
  const glm::vec2 bary = glm::inverse(glm::mat2(e1, e2)) * (target - uv0);
  const unsigned char* px =
      pixels + (std::size_t(texel.y) * std::size_t(w) + std::size_t(texel.x)) * 4;
  const glm::vec4 expected = m.baseColorFactor * glm::vec4(srgbToLinear(px[0]), srgbToLinear(px[1]),
                                                           srgbToLinear(px[2]), px[3] / 255.0f);
  const glm::vec4 got = sampleAlbedo(scene, 0, bary);
  EXPECT_NEAR(got.r, expected.r, 2e-3f);
  EXPECT_NEAR(got.g, expected.g, 2e-3f);
  EXPECT_NEAR(got.b, expected.b, 2e-3f);
  EXPECT_NEAR(got.a, expected.a, 2e-3f);
  stbi_image_free(pixels);
  EXPECT_EQ(sampleEmission(scene, 0, bary), glm::vec3(0.0f));
}

TEST(GltfImport, BinaryAndEmbeddedVariantsMatch) {
  const TriangleScene a = loadGltf(model("BoxTextured-glTF/BoxTextured.gltf"));
  for (const char* other :
       {"BoxTextured-glTF-Binary/BoxTextured.glb", "BoxTextured-glTF-Embedded/BoxTextured.gltf"}) {
    const TriangleScene b = loadGltf(model(other));
    EXPECT_EQ(b.triangles, a.triangles) << other;
    EXPECT_EQ(b.positions, a.positions) << other;
    EXPECT_EQ(b.uvs, a.uvs) << other;
    ASSERT_EQ(b.textures.size(), 1u) << other;
    EXPECT_EQ(b.textures[0].rgba, a.textures[0].rgba) << other;
  }
}

TEST(GltfImport, TwoCylinderEngine) {
  const TriangleScene scene = loadGltf(model("2CylinderEngine-glTF-Binary/2CylinderEngine.glb"));
  EXPECT_EQ(scene.triangles.size(), 121496u);  // sum over node instances, counted from the JSON
  EXPECT_EQ(scene.triangleMaterial.size(), scene.triangles.size());
  for (const glm::vec3& p : scene.positions)
    ASSERT_TRUE(std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z));
  for (const glm::uvec3& t : scene.triangles)
    ASSERT_TRUE(t.x < scene.positions.size() && t.y < scene.positions.size() &&
                t.z < scene.positions.size());
  for (std::uint32_t m : scene.triangleMaterial) ASSERT_LT(m, scene.materials.size());
  EXPECT_GT(scene.surfaceArea(), 0.0);
}

// Parent: matrix = translate(1,2,3) * scale(2); child: translate(0,0,1) * rotate 90° about z.
TEST(GltfImport, NodeTransformsCompose) {
  const fs::path dir = test::scratchDir("gltf-nodes");
  nlohmann::json j = test::gltfWithPositions(dir, "tri", {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}});
  j["meshes"] = {{{"primitives", {{{"attributes", {{"POSITION", 0}}}}}}}};
  const float h = std::sqrt(0.5f);
  j["nodes"] = {{{"children", {1}}, {"matrix", {2, 0, 0, 0, 0, 2, 0, 0, 0, 0, 2, 0, 1, 2, 3, 1}}},
                {{"mesh", 0}, {"translation", {0, 0, 1}}, {"rotation", {0, 0, h, h}}}};
  j["scenes"] = {{{"nodes", {0}}}};
  j["scene"] = 0;
  const TriangleScene scene = loadGltf(test::save(dir, "tri", j));
  ASSERT_EQ(scene.triangles.size(), 1u);
  const glm::uvec3 t = scene.triangles[0];
  expectNear(scene.positions[t.x], {1, 2, 5});
  expectNear(scene.positions[t.y], {1, 4, 5});
  expectNear(scene.positions[t.z], {-1, 2, 5});
  EXPECT_NEAR(scene.surfaceArea(), 2.0, 1e-5);  // 0.5 * 2²
  ASSERT_EQ(scene.materials.size(), 1u);        // the default grey
  EXPECT_EQ(scene.materials[0].baseColorFactor, glm::vec4(0.8f, 0.8f, 0.8f, 1.0f));
}

TEST(GltfImport, MirroringKeepsOutwardWinding) {
  const fs::path dir = test::scratchDir("gltf-mirror");
  nlohmann::json j = test::gltfWithPositions(dir, "tri", {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}});
  j["meshes"] = {{{"primitives", {{{"attributes", {{"POSITION", 0}}}}}}}};
  j["nodes"] = {{{"mesh", 0}, {"scale", {1, 1, -1}}}};
  const TriangleScene scene = loadGltf(test::save(dir, "tri", j));
  const glm::uvec3 t = scene.triangles[0];
  const glm::vec3 n = glm::cross(scene.positions[t.y] - scene.positions[t.x],
                                 scene.positions[t.z] - scene.positions[t.x]);
  // The source faces +z; a true normal transforms by M^-T = diag(1,1,-1), so it must face -z.
  EXPECT_LT(n.z, 0.0f);
}

TEST(GltfImport, StripsAndFansAndSkippedLines) {
  const fs::path dir = test::scratchDir("gltf-strips");
  nlohmann::json j =
      test::gltfWithPositions(dir, "quad", {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0}});
  j["meshes"] = {{{"primitives",
                   {{{"attributes", {{"POSITION", 0}}}, {"mode", 5}},
                    {{"attributes", {{"POSITION", 0}}}, {"mode", 6}},
                    {{"attributes", {{"POSITION", 0}}}, {"mode", 1}}}}}};
  j["nodes"] = {{{"mesh", 0}}};
  const TriangleScene scene = loadGltf(test::save(dir, "quad", j));
  ASSERT_EQ(scene.triangles.size(), 4u);  // 2 from the strip, 2 from the fan, none from lines
  EXPECT_EQ(scene.triangles[0], glm::uvec3(0, 1, 2));
  EXPECT_EQ(scene.triangles[1], glm::uvec3(1, 3, 2));  // glTF: odd triangles swap the last two
  EXPECT_EQ(scene.triangles[2], glm::uvec3(5, 6, 4));  // fan around vertex 0 (offset 4)
  EXPECT_NEAR(scene.surfaceArea(), 2.0, 1e-5);
}

TEST(GltfImport, EmissiveStrengthAboveOneIsKept) {
  const fs::path dir = test::scratchDir("gltf-emissive");
  nlohmann::json j = test::gltfWithPositions(dir, "lamp", {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}});
  j["meshes"] = {{{"primitives", {{{"attributes", {{"POSITION", 0}}}, {"material", 0}}}}}};
  j["nodes"] = {{{"mesh", 0}}};
  j["extensionsUsed"] = {"KHR_materials_emissive_strength"};
  j["materials"] = {
      {{"name", "lamp"},
       {"emissiveFactor", {1.0, 0.5, 0.25}},
       {"extensions", {{"KHR_materials_emissive_strength", {{"emissiveStrength", 8.0}}}}}}};
  const TriangleScene scene = loadGltf(test::save(dir, "lamp", j));
  ASSERT_EQ(scene.materials.size(), 1u);
  expectNear(scene.materials[0].emissive, {8.0f, 4.0f, 2.0f});
  expectNear(sampleEmission(scene, 0, {0.25f, 0.25f}), {8.0f, 4.0f, 2.0f});
  EXPECT_EQ(sampleAlbedo(scene, 0, {0.25f, 0.25f}), glm::vec4(1.0f));  // glTF default factor
}

TEST(GltfImport, CornellBoxLightIsHdr) {
  SDFSTREAM_REQUIRE_SHARED_DATA("cornell-box/CornellBox-Original.glb");
  const TriangleScene scene = loadGltf(test::sharedData() / "cornell-box/CornellBox-Original.glb");
  EXPECT_EQ(scene.triangles.size(), 36u);
  bool foundLight = false;
  for (std::uint32_t t = 0; t < scene.triangles.size(); ++t) {
    const glm::vec3 e = sampleEmission(scene, t, {1.0f / 3, 1.0f / 3});
    if (e != glm::vec3(0.0f)) {
      expectNear(e, {17.0f, 12.0f, 4.0f});
      EXPECT_EQ(scene.materials[scene.triangleMaterial[t]].name, "light");
      foundLight = true;
    }
  }
  EXPECT_TRUE(foundLight);
}

}  // namespace
}  // namespace sdfstream
