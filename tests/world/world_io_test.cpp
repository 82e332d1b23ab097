// World directory I/O: round trip, determinism, corruption and atomicity.
#include <fstream>
#include <iterator>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <glm/gtc/matrix_transform.hpp>

#include "core/error.h"
#include "tests/support/test_data.h"
#include "tests/world/mesh_fixtures.h"
#include "world/import.h"
#include "world/mesh_to_sdf.h"
#include "world/world_io.h"

namespace sdfstream {
namespace {

namespace fs = std::filesystem;

std::vector<char> bytes(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}
void writeBytes(const fs::path& p, const std::vector<char>& b) {
  std::ofstream(p, std::ios::binary | std::ios::trunc).write(b.data(), std::streamsize(b.size()));
}

World testWorld() {
  TriangleScene s = test::icosphere({0.1f, 0.2f, 0.3f}, 1.0f, 2);
  s.source = "/some/dir/sphere.gltf";
  return meshToWorld(s, 0.1, {});
}

InputError readError(const fs::path& dir) {
  try {
    readWorld(dir);
  } catch (const InputError& e) {
    return e;
  }
  ADD_FAILURE() << "readWorld succeeded";
  return InputError(InputErrorKind::Io, "", "");
}

void expectNoTempLeft(const fs::path& parent) {
  for (const auto& entry : fs::directory_iterator(parent))
    EXPECT_EQ(entry.path().filename().string().find(".tmp-"), std::string::npos) << entry.path();
}

TEST(WorldIo, RoundTrip) {
  const fs::path dir = test::scratchDir("world-roundtrip") / "out";
  World w = testWorld();
  writeWorld(w, dir);
  World r = readWorld(dir);
  EXPECT_EQ(r.voxelSize, w.voxelSize);
  EXPECT_EQ(r.origin, w.origin);
  EXPECT_EQ(r.source, "sphere.gltf");
  EXPECT_EQ(r.indexMin(), w.indexMin());
  EXPECT_EQ(r.indexMax(), w.indexMax());
  ASSERT_EQ(r.bricks.size(), w.bricks.size());
  for (std::size_t i = 0; i < w.bricks.size(); ++i) {
    ASSERT_EQ(r.bricks[i].coord, w.bricks[i].coord);
    ASSERT_EQ(r.bricks[i].distance, w.bricks[i].distance);
    ASSERT_EQ(r.bricks[i].albedo, w.bricks[i].albedo);
    ASSERT_EQ(r.bricks[i].emission, w.bricks[i].emission);
  }
  expectNoTempLeft(dir.parent_path());
}

TEST(WorldIo, SameInputGivesIdenticalBytes) {
  const fs::path root = test::scratchDir("world-determinism");
  writeWorld(testWorld(), root / "a");
  writeWorld(testWorld(), root / "b");
  EXPECT_EQ(bytes(root / "a/world.json"), bytes(root / "b/world.json"));
  EXPECT_EQ(bytes(root / "a/bricks.bin"), bytes(root / "b/bricks.bin"));
  // Through the importer, from a file (needs the Debian-packaged glTF and the glTF loader).
  const fs::path gltf = test::assimpModels() / "glTF2/BoxTextured-glTF/BoxTextured.gltf";
  if (!fs::exists(gltf)) GTEST_SKIP() << gltf << " absent";
  const ImportOptions options{.voxelSize = 1.0 / 64.0, .limits = {}};
  importToDirectory(gltf, root / "c", options);
  importToDirectory(gltf, root / "d", options);
  EXPECT_EQ(bytes(root / "c/world.json"), bytes(root / "d/world.json"));
  EXPECT_EQ(bytes(root / "c/bricks.bin"), bytes(root / "d/bricks.bin"));
  EXPECT_FALSE(readWorld(root / "c").bricks.empty());
}

TEST(WorldIo, FlippedByteNamesTheSection) {
  const fs::path root = test::scratchDir("world-checksum");
  World w = testWorld();
  writeWorld(w, root / "clean");
  const std::vector<char> clean = bytes(root / "clean/bricks.bin");
  const std::size_t n = w.bricks.size();
  // Offsets of the middle of each section (layout in world_io.h).
  const std::size_t coords = 120, distances = coords + ((n * 12 + 7) & ~std::size_t(7));
  const std::size_t albedo = distances + ((n * 1458 + 7) & ~std::size_t(7));
  const std::size_t emission = albedo + n * 2048;
  const std::pair<std::size_t, const char*> cases[] = {{coords + n * 6, "coords"},
                                                       {distances + n * 729, "distances"},
                                                       {albedo + n * 1024, "albedo"},
                                                       {emission + n * 1024, "emission"}};
  for (auto [offset, section] : cases) {
    fs::copy(root / "clean", root / section, fs::copy_options::recursive);
    std::vector<char> b = clean;
    b.at(offset) ^= 0x10;
    writeBytes(root / section / "bricks.bin", b);
    InputError e = readError(root / section);
    EXPECT_EQ(e.kind(), InputErrorKind::Checksum) << e.what();
    EXPECT_NE(std::string(e.what()).find(section), std::string::npos) << e.what();
  }
}

TEST(WorldIo, TruncatedAndBadVersion) {
  const fs::path root = test::scratchDir("world-truncated");
  writeWorld(testWorld(), root / "w");
  const std::vector<char> clean = bytes(root / "w/bricks.bin");
  for (std::size_t size : {clean.size() - 1, clean.size() / 2, std::size_t(100), std::size_t(0)}) {
    writeBytes(root / "w/bricks.bin", {clean.begin(), clean.begin() + std::ptrdiff_t(size)});
    InputError e = readError(root / "w");
    EXPECT_EQ(e.kind(), InputErrorKind::Truncated) << size << ": " << e.what();
  }
  std::vector<char> b = clean;
  b[8] = 7;  // version
  writeBytes(root / "w/bricks.bin", b);
  EXPECT_EQ(readError(root / "w").kind(), InputErrorKind::Version);
  b = clean;
  b[0] = 'X';  // magic
  writeBytes(root / "w/bricks.bin", b);
  EXPECT_EQ(readError(root / "w").kind(), InputErrorKind::Malformed);
}

TEST(WorldIo, FailedImportKeepsExistingOutput) {
  const fs::path root = test::scratchDir("world-atomic");
  const fs::path out = root / "out";
  writeWorld(testWorld(), out);
  const auto json = bytes(out / "world.json"), bin = bytes(out / "bricks.bin");
  const fs::path bad = root / "garbage.vdb";
  writeBytes(bad, std::vector<char>(4096, 'x'));
  EXPECT_THROW(importToDirectory(bad, out, {}), InputError);
  EXPECT_THROW(importToDirectory(root / "scene.unknown", out, {}), InputError);
  EXPECT_EQ(bytes(out / "world.json"), json);
  EXPECT_EQ(bytes(out / "bricks.bin"), bin);
  EXPECT_THROW(importToDirectory(bad, root / "fresh", {}), InputError);
  EXPECT_FALSE(fs::exists(root / "fresh"));
  expectNoTempLeft(root);
}

TEST(WorldIo, UnknownExtensionIsUsage) {
  try {
    importScene("scene.fbx", {});
    FAIL();
  } catch (const InputError& e) {
    EXPECT_EQ(e.kind(), InputErrorKind::Usage);
  }
}

}  // namespace
}  // namespace sdfstream
