// The object library: indices, names, versions, and the disk cache (hits without rebuilding,
// corrupt files rebuilt with a warning, identical results either way).
#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>

#include "core/error.h"
#include "objects/object_cache.h"
#include "objects/object_library.h"
#include "objects/primitive_meshes.h"
#include "tests/support/object_sdf_settings.h"
#include "tests/support/test_data.h"

namespace sdfstream {
namespace {

namespace fs = std::filesystem;

std::vector<fs::path> filesIn(const fs::path& dir) {
  std::vector<fs::path> out;
  for (const auto& e : fs::directory_iterator(dir)) out.push_back(e.path());
  return out;
}

void expectSame(const ObjectSdf& a, const ObjectSdf& b) {
  EXPECT_EQ(a.contentHash(), b.contentHash());
  EXPECT_EQ(a.dims, b.dims);
  EXPECT_EQ(a.distance, b.distance);
  EXPECT_EQ(a.albedo, b.albedo);
  EXPECT_EQ(a.emission, b.emission);
  EXPECT_EQ(a.closed, b.closed);
  EXPECT_EQ(a.meshMin, b.meshMin);
}

TEST(ObjectLibrary, IndicesNamesAndVersion) {
  ObjectLibrary lib(test::objectSdfResolution(16));
  EXPECT_EQ(lib.size(), 0u);
  EXPECT_EQ(lib.version(), 0u);
  const std::uint32_t box = lib.addBox(glm::vec3(0.5f, 1.0f, 0.25f), glm::vec4(1.0f));
  const ObjectSdf* first = &lib.mesh(box);
  const std::uint32_t sphere = lib.addSphere(0.75f, glm::vec4(0.5f), 8);
  EXPECT_EQ(box, 0u);
  EXPECT_EQ(sphere, 1u);
  EXPECT_EQ(lib.size(), 2u);
  EXPECT_EQ(lib.version(), 2u);
  EXPECT_EQ(&lib.mesh(box), first);  // adds never move earlier meshes
  EXPECT_EQ(lib.name(box), "box(0.5,1,0.25)");
  EXPECT_EQ(lib.name(sphere), "sphere(0.75)");
  EXPECT_EQ(lib.find("sphere(0.75)"), sphere);
  EXPECT_FALSE(lib.find("nothing").has_value());
  EXPECT_NEAR(lib.mesh(box).meshMax.y, 1.0f, 1e-6f);
  EXPECT_NEAR(lib.mesh(sphere).meshMax.x, 0.75f, 1e-6f);
  EXPECT_THROW(lib.mesh(2), std::out_of_range);
  EXPECT_EQ(lib.cacheStats().built, 2u);
  EXPECT_EQ(lib.cacheStats().loaded, 0u);
  // A failed add leaves the library as it was.
  TriangleScene bad = makeBoxMesh(glm::vec3(1.0f), glm::vec4(1.0f));
  bad.triangles.clear();
  EXPECT_THROW(lib.add("bad", bad), InputError);
  EXPECT_EQ(lib.size(), 2u);
  EXPECT_EQ(lib.version(), 2u);
}

TEST(ObjectLibrary, GltfFileIsOneMesh) {
  const fs::path file = test::assimpModels() / "glTF2/BoxTextured-glTF/BoxTextured.gltf";
  if (!fs::exists(file)) GTEST_SKIP() << file << " absent (assimp-testmodels)";
  ObjectLibrary lib(test::objectSdfResolution(16));
  const std::uint32_t i = lib.addGltf(file);
  EXPECT_EQ(lib.name(i), "BoxTextured.gltf");
  EXPECT_TRUE(lib.mesh(i).closed);
  EXPECT_THROW(lib.addGltf(test::sourceDir() / "no-such-file.glb"), InputError);
}

TEST(ObjectLibrary, DiskCacheHitsSkipTheBuildAndCorruptFilesAreRebuilt) {
  const fs::path dir = test::scratchDir("object-cache") / "nested";  // created on first write
  const TriangleScene sphere = makeSphereMesh(0.5f, glm::vec4(0.2f, 0.4f, 0.6f, 1.0f), 10);

  ObjectLibrary first(test::objectSdfResolution(16), dir);
  const ObjectSdf& built = first.mesh(first.add("s", sphere));
  EXPECT_EQ(first.cacheStats().built, 1u);
  EXPECT_EQ(first.cacheStats().loaded, 0u);
  const std::vector<fs::path> files = filesIn(dir);
  ASSERT_EQ(files.size(), 1u);  // no temp file left behind
  EXPECT_EQ(files[0].filename(),
            objectCacheFileName(objectCacheKey(sphere, test::objectSdfResolution(16))));

  ObjectLibrary second(test::objectSdfResolution(16), dir);
  const ObjectSdf& loaded = second.mesh(second.add("s", sphere));
  EXPECT_EQ(second.cacheStats().built, 0u);
  EXPECT_EQ(second.cacheStats().loaded, 1u);
  expectSame(built, loaded);
  EXPECT_EQ(second.version(), 1u);

  // Different settings or a different mesh: a different file, built.
  ObjectSdfSettings padded = test::objectSdfResolution(16);
  padded.padVoxels = 3;
  ObjectLibrary other(padded, dir);
  other.add("s", sphere);
  TriangleScene recoloured = sphere;
  recoloured.materials[0].baseColorFactor.r = 0.9f;
  other.add("s2", recoloured);
  EXPECT_EQ(other.cacheStats().built, 2u);
  EXPECT_EQ(filesIn(dir).size(), 3u);

  // Flip one byte in the middle of the first file: rebuilt with a one-line warning, file fixed.
  {
    std::fstream f(files[0], std::ios::in | std::ios::out | std::ios::binary);
    f.seekg(std::streamoff(fs::file_size(files[0]) / 2));
    const char c = char(f.get());
    f.seekp(std::streamoff(fs::file_size(files[0]) / 2));
    f.put(char(c ^ 0x5a));
  }
  testing::internal::CaptureStderr();
  ObjectLibrary third(test::objectSdfResolution(16), dir);
  const ObjectSdf& rebuilt = third.mesh(third.add("s", sphere));
  const std::string warning = testing::internal::GetCapturedStderr();
  EXPECT_EQ(third.cacheStats().corrupt, 1u);
  EXPECT_EQ(third.cacheStats().built, 1u);
  EXPECT_NE(warning.find(files[0].filename().string()), std::string::npos) << warning;
  EXPECT_NE(warning.find("checksum"), std::string::npos) << warning;
  EXPECT_EQ(std::count(warning.begin(), warning.end(), '\n'), 1) << warning;
  expectSame(built, rebuilt);

  ObjectLibrary fourth(test::objectSdfResolution(16), dir);
  fourth.add("s", sphere);
  EXPECT_EQ(fourth.cacheStats().loaded, 1u);

  // Truncated: also a miss with a warning, never an exception.
  fs::resize_file(files[0], 50);
  testing::internal::CaptureStderr();
  ObjectLibrary fifth(test::objectSdfResolution(16), dir);
  expectSame(built, fifth.mesh(fifth.add("s", sphere)));
  EXPECT_NE(testing::internal::GetCapturedStderr().find("shorter"), std::string::npos);
  EXPECT_EQ(fifth.cacheStats().corrupt, 1u);
  fs::remove_all(dir.parent_path());
}

TEST(ObjectCache, ParseRejectsEveryTruncationAndWrongKey) {
  ObjectSdfSettings tiny;
  tiny.minResolution = tiny.maxResolution = 3;
  tiny.padVoxels = 0;
  const ObjectSdf sdf = buildObjectSdf(makeBoxMesh(glm::vec3(1.0f), glm::vec4(1.0f)), tiny);
  const std::vector<std::uint8_t> bytes = serializeObjectSdf(sdf, 42);
  std::string problem;
  ASSERT_TRUE(parseObjectSdf(bytes, 42, &problem).has_value()) << problem;
  EXPECT_FALSE(parseObjectSdf(bytes, 43, &problem).has_value());
  EXPECT_EQ(problem, "key does not match its name");
  for (std::size_t n = 0; n < bytes.size(); ++n)
    ASSERT_FALSE(parseObjectSdf(std::span(bytes.data(), n), 42, &problem).has_value()) << n;
  for (std::size_t i = 0; i < bytes.size(); i += 7) {  // any flipped byte is caught
    std::vector<std::uint8_t> bad = bytes;
    bad[i] ^= 0x01;
    ASSERT_FALSE(parseObjectSdf(bad, 42, &problem).has_value()) << i;
  }
}

}  // namespace
}  // namespace sdfstream
