// World packs (world/pack.h): exact round trip, byte-identical output (also from several threads
// and through shards + merge), corruption, truncation, versions, bad manifests and disk full.
#include <sys/mount.h>

#include <algorithm>
#include <cstdlib>
#include <fstream>
#include <iterator>
#include <map>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

#include "core/error.h"
#include "tests/support/test_data.h"
#include "world/pack.h"
#include "world/pack_format.h"
#include "world/world_io.h"

namespace sdfstream {
namespace {

namespace fs = std::filesystem;

std::string bytes(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}
void writeBytes(const fs::path& p, const std::string& b) {
  std::ofstream(p, std::ios::binary | std::ios::trunc) << b;
}

// Every file under a directory, by relative name.
std::map<std::string, std::string> tree(const fs::path& dir) {
  std::map<std::string, std::string> files;
  for (const auto& e : fs::recursive_directory_iterator(dir))
    if (e.is_regular_file()) files[fs::relative(e.path(), dir).string()] = bytes(e.path());
  return files;
}

bool sameBrick(const Brick& a, const Brick& b) {
  return a.coord == b.coord && a.distance == b.distance && a.albedo == b.albedo &&
         a.emission == b.emission;
}

PartitionSpec testSpec() {
  PartitionSpec s;
  s.voxelSize = 0.25;
  s.lodCount = 3;
  s.tileVoxels = 64;  // bricks per tile edge: 8, 4, 2
  s.origin = {1.5, -2.0, 0.25};
  return s;
}

// A tile with a seeded random subset of slots per LOD; distances smooth enough to compress.
Tile makeTile(const PartitionSpec& spec, glm::ivec3 coord, unsigned seed, double fill) {
  std::mt19937 rng(seed);
  Tile t;
  t.coord = coord;
  t.lods.resize(spec.lodCount);
  for (int l = 0; l < spec.lodCount; ++l) {
    const int n = spec.tileBricks(l);
    TileLod& lod = t.lods[l];
    lod.emptyDistance.assign(std::size_t(n) * n * n, 0);
    for (int z = 0; z < n; ++z)
      for (int y = 0; y < n; ++y)
        for (int x = 0; x < n; ++x) {
          const std::size_t slot = std::size_t(x + n * (y + n * z));
          if (std::uniform_real_distribution<double>(0, 1)(rng) >= fill) {
            lod.emptyDistance[slot] = std::uint8_t(1 + rng() % 4);
            continue;
          }
          Brick b;
          b.coord = coord * n + glm::ivec3(x, y, z);
          const int base = int(rng() % 2000);
          for (std::size_t i = 0; i < b.distance.size(); ++i)
            b.distance[i] = std::uint16_t(0x3c00 + base + int(i % 81) * 3 + int(rng() % 4));
          for (std::size_t i = 0; i < b.albedo.size(); ++i) {
            b.albedo[i] = 0xff204080u + (rng() % 3);
            b.emission[i] = i % 7 == 0 ? std::uint32_t(rng()) : 0u;
          }
          lod.bricks.push_back(b);
        }
  }
  return t;
}

std::vector<Tile> testTiles(const PartitionSpec& spec) {
  return {makeTile(spec, {0, 0, 0}, 1, 0.3), makeTile(spec, {-1, 0, 2}, 2, 0.2),
          makeTile(spec, {1, -1, 0}, 3, 0.1), makeTile(spec, {0, 0, 1}, 4, 0.25),
          makeTile(spec, {5, 5, 5}, 5, 0.0)};  // no bricks: not stored
}

const glm::dvec3 kBoundsMin{-10, -5, 0}, kBoundsMax{20, 4, 30};

void writePack(const fs::path& dir, const std::vector<Tile>& tiles,
               const PartitionSpec& spec = testSpec()) {
  PackWriter w(dir, spec);
  for (const Tile& t : tiles) w.addTile(t);
  w.commit(kBoundsMin, kBoundsMax, "test.gltf", {"stone", "lamp"});
}

template <typename F>
InputError errorOf(F&& f) {
  try {
    f();
  } catch (const InputError& e) {
    return e;
  }
  ADD_FAILURE() << "no InputError thrown";
  return InputError(InputErrorKind::Usage, "", "none");
}

void expectOnlyEntry(const fs::path& parent, const std::string& name) {
  for (const auto& e : fs::directory_iterator(parent))
    EXPECT_EQ(e.path().filename().string(), name) << "left behind: " << e.path();
}

TEST(Pack, RoundTripIsExact) {
  const fs::path dir = test::scratchDir("pack-roundtrip") / "world";
  const PartitionSpec spec = testSpec();
  const std::vector<Tile> tiles = testTiles(spec);
  writePack(dir, tiles);

  const PackManifest m = readManifest(dir);
  EXPECT_EQ(m.spec.voxelSize, spec.voxelSize);
  EXPECT_EQ(m.spec.lodCount, spec.lodCount);
  EXPECT_EQ(m.spec.tileVoxels, spec.tileVoxels);
  EXPECT_EQ(m.spec.origin, spec.origin);
  EXPECT_EQ(m.boundsMin, kBoundsMin);
  EXPECT_EQ(m.boundsMax, kBoundsMax);
  EXPECT_EQ(m.source, "test.gltf");
  EXPECT_EQ(m.materials, (std::vector<std::string>{"stone", "lamp"}));
  ASSERT_EQ(m.tiles.size(), 4u) << "the empty tile is not stored";
  // Sorted (z, y, x): (1,-1,0), (0,0,0), (0,0,1), (-1,0,2).
  EXPECT_EQ(m.tiles[0].coord, glm::ivec3(1, -1, 0));
  EXPECT_EQ(m.tiles[1].coord, glm::ivec3(0, 0, 0));
  EXPECT_EQ(m.tiles[2].coord, glm::ivec3(0, 0, 1));
  EXPECT_EQ(m.tiles[3].coord, glm::ivec3(-1, 0, 2));
  EXPECT_EQ(m.tiles[3].file, "tiles/-1_0_2.tile");
  EXPECT_FALSE(fs::exists(dir / "tiles/5_5_5.tile"));

  std::vector<std::vector<Brick>> all(spec.lodCount);
  for (const Tile& t : tiles) {
    for (int l = 0; l < spec.lodCount; ++l)
      all[l].insert(all[l].end(), t.lods[l].bricks.begin(), t.lods[l].bricks.end());
    auto it = std::find_if(m.tiles.begin(), m.tiles.end(),
                           [&](const TileEntry& e) { return e.coord == t.coord; });
    if (it == m.tiles.end()) continue;
    EXPECT_EQ(fs::file_size(dir / it->file), it->bytes);
    const Tile r = readTile(dir, *it, m.spec);
    const Tile byLodCount = readTile(dir, *it, m.spec.lodCount);  // edge from the tile itself
    for (int l = 0; l < spec.lodCount; ++l)
      EXPECT_EQ(byLodCount.lods[l].bricks.size(), t.lods[l].bricks.size());
    EXPECT_EQ(r.coord, t.coord);
    ASSERT_EQ(r.lods.size(), t.lods.size());
    for (int l = 0; l < spec.lodCount; ++l) {
      EXPECT_EQ(it->bricksPerLod[l], t.lods[l].bricks.size());
      EXPECT_EQ(r.lods[l].emptyDistance, t.lods[l].emptyDistance);
      ASSERT_EQ(r.lods[l].bricks.size(), t.lods[l].bricks.size());
      for (std::size_t i = 0; i < t.lods[l].bricks.size(); ++i)
        EXPECT_TRUE(sameBrick(r.lods[l].bricks[i], t.lods[l].bricks[i])) << l << " " << i;
    }
  }
  for (int l = 0; l < spec.lodCount; ++l) {
    std::sort(all[l].begin(), all[l].end(),
              [](const Brick& a, const Brick& b) { return brickCoordLess(a.coord, b.coord); });
    const World w = loadLod(dir, l);
    EXPECT_EQ(w.voxelSize, spec.voxelSize * double(1 << l));
    EXPECT_EQ(w.origin, spec.origin);
    EXPECT_EQ(w.source, "test.gltf");
    ASSERT_EQ(w.bricks.size(), all[l].size());
    for (std::size_t i = 0; i < all[l].size(); ++i)
      EXPECT_TRUE(sameBrick(w.bricks[i], all[l][i])) << l << " " << i;
  }
  EXPECT_EQ(verifyPack(dir), "");
  EXPECT_EQ(errorOf([&] { loadLod(dir, 3); }).kind(), InputErrorKind::OutOfRange);
  expectOnlyEntry(dir.parent_path(), "world");
}

TEST(Pack, IdenticalInputGivesIdenticalBytesFromAnyThreadOrder) {
  const fs::path root = test::scratchDir("pack-determinism");
  const PartitionSpec spec = testSpec();
  const std::vector<Tile> tiles = testTiles(spec);
  writePack(root / "a", tiles);
  writePack(root / "b", tiles);
  const auto a = tree(root / "a");
  EXPECT_EQ(a.size(), 5u);
  EXPECT_EQ(a, tree(root / "b"));
  for (unsigned seed = 0; seed < 3; ++seed) {
    std::vector<Tile> shuffled = tiles;
    std::shuffle(shuffled.begin(), shuffled.end(), std::mt19937(seed));
    PackWriter w(root / "c", spec);
    std::vector<std::thread> threads;
    for (std::size_t k = 0; k < 3; ++k)
      threads.emplace_back([&, k] {
        for (std::size_t i = k; i < shuffled.size(); i += 3) w.addTile(shuffled[i]);
      });
    for (auto& t : threads) t.join();
    w.commit(kBoundsMin, kBoundsMax, "test.gltf", {"stone", "lamp"});
    EXPECT_EQ(tree(root / "c"), a) << "seed " << seed;
  }
}

TEST(Pack, FlippedByteIsFoundAndNamesTheTile) {
  const fs::path root = test::scratchDir("pack-flip");
  const PartitionSpec spec = testSpec();
  writePack(root / "w", testTiles(spec));
  const PackManifest m = readManifest(root / "w");
  const TileEntry& entry = m.tiles[2];  // tiles/0_0_1.tile
  ASSERT_EQ(entry.file, "tiles/0_0_1.tile");
  const fs::path file = root / "w" / entry.file;
  const std::string clean = bytes(file);

  // Every header byte and a sample of payload bytes: verify always names this tile.
  std::vector<std::size_t> offsets;
  for (std::size_t i = 0; i < pack_format::tileHeaderBytes(spec.lodCount); ++i)
    offsets.push_back(i);
  std::mt19937 rng(7);
  for (int k = 0; k < 64; ++k) offsets.push_back(rng() % clean.size());
  offsets.push_back(clean.size() - 1);
  for (std::size_t at : offsets) {
    std::string b = clean;
    b[at] = char(b[at] ^ 0x10);
    writeBytes(file, b);
    const std::string problem = verifyPack(root / "w");
    EXPECT_EQ(problem.rfind("tiles/0_0_1.tile: ", 0), 0u) << "byte " << at << ": " << problem;
    EXPECT_EQ(problem.find('\n'), std::string::npos);
  }

  // A payload byte of LOD 2: the section is named and readTile throws Checksum.
  const std::size_t lod2 = clean.size() - 5;
  std::string b = clean;
  b[lod2] = char(b[lod2] ^ 0x01);
  writeBytes(file, b);
  EXPECT_EQ(verifyPack(root / "w"), "tiles/0_0_1.tile: section lod2 checksum mismatch");
  const InputError e = errorOf([&] { readTile(root / "w", entry, m.spec); });
  EXPECT_EQ(e.kind(), InputErrorKind::Checksum) << e.what();
  EXPECT_NE(std::string(e.what()).find("0_0_1.tile"), std::string::npos) << e.what();
  EXPECT_THROW(loadLod(root / "w", 0), InputError);

  writeBytes(file, clean);
  EXPECT_EQ(verifyPack(root / "w"), "");
}

TEST(Pack, TruncatedTileAndWrongVersion) {
  const fs::path root = test::scratchDir("pack-truncated");
  writePack(root / "w", testTiles(testSpec()));
  const PackManifest m = readManifest(root / "w");
  const TileEntry& entry = m.tiles[1];
  const fs::path file = root / "w" / entry.file;
  const std::string clean = bytes(file);
  for (std::size_t size :
       {std::size_t(0), std::size_t(20), std::size_t(100), clean.size() / 2, clean.size() - 1}) {
    writeBytes(file, clean.substr(0, size));
    const InputError e = errorOf([&] { readTile(root / "w", entry, m.spec); });
    EXPECT_EQ(e.kind(), InputErrorKind::Truncated) << size << ": " << e.what();
    EXPECT_EQ(verifyPack(root / "w").rfind(entry.file + ": ", 0), 0u);
  }
  // Truncated, with the manifest agreeing on the size (a tile cut and re-registered).
  {
    std::string text = bytes(root / "w/manifest.json");
    const std::string from = "\"bytes\":" + std::to_string(entry.bytes);
    const std::size_t at = text.find(from);
    ASSERT_NE(at, std::string::npos);
    const fs::path copy = root / "cut";
    fs::copy(root / "w", copy, fs::copy_options::recursive);
    writeBytes(copy / entry.file, clean.substr(0, clean.size() - 3));
    text.replace(at, from.size(), "\"bytes\":" + std::to_string(entry.bytes - 3));
    writeBytes(copy / "manifest.json", text);
    EXPECT_EQ(errorOf([&] { readTile(copy, readManifest(copy).tiles[1], m.spec); }).kind(),
              InputErrorKind::Truncated);
  }
  std::string b = clean;
  b[8] = 2;  // version u32 at offset 8
  writeBytes(file, b);
  const InputError e = errorOf([&] { readTile(root / "w", entry, m.spec); });
  EXPECT_EQ(e.kind(), InputErrorKind::Version) << e.what();
  EXPECT_NE(verifyPack(root / "w").find("version 2"), std::string::npos);
}

TEST(Pack, BadManifestNamesTheKey) {
  const fs::path root = test::scratchDir("pack-manifest");
  writePack(root / "w", testTiles(testSpec()));
  const std::string clean = bytes(root / "w/manifest.json");
  auto expectError = [&](const std::string& text, InputErrorKind kind, const std::string& key) {
    writeBytes(root / "w/manifest.json", text);
    const InputError e = errorOf([&] { readManifest(root / "w"); });
    EXPECT_EQ(e.kind(), kind) << e.what();
    EXPECT_NE(std::string(e.what()).find(key), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("manifest.json"), std::string::npos) << e.what();
    EXPECT_NE(verifyPack(root / "w").find(key), std::string::npos);
  };
  auto replaced = [&](const std::string& from, const std::string& to) {
    std::string t = clean;
    const std::size_t at = t.find(from);
    EXPECT_NE(at, std::string::npos) << from;
    return t.replace(at, from.size(), to);
  };
  expectError(clean.substr(0, clean.size() / 2), InputErrorKind::Malformed, "not valid JSON");
  expectError("[1, 2]", InputErrorKind::Malformed, "not a JSON object");
  expectError(replaced("\"tileVoxels\"", "\"tileVoxelz\""), InputErrorKind::Malformed,
              "'partition.tileVoxels': missing");
  expectError(replaced("\"bytes\":", "\"bytes\":\"x\",\"_\":"), InputErrorKind::Malformed,
              "'tiles[0].bytes': expected a non-negative integer");
  expectError(replaced("\"lodCount\": 3", "\"lodCount\": 2.5"), InputErrorKind::Malformed,
              "'partition.lodCount'");
  expectError(replaced("\"tileVoxels\": 64", "\"tileVoxels\": 60"), InputErrorKind::Malformed,
              "'partition': tileVoxels must be a positive multiple of 32");
  expectError(replaced("\"file\":\"tiles/1_-1_0.tile\"", "\"file\":\"../../etc/passwd\""),
              InputErrorKind::Malformed, "'tiles[0].file'");
  expectError(replaced("\"sdfstream-pack\"", "\"sdfstream-world\""), InputErrorKind::Version,
              "format");
  expectError(replaced("\"version\": 1", "\"version\": 9"), InputErrorKind::Version, "version 9");
  fs::remove(root / "w/manifest.json");
  EXPECT_EQ(errorOf([&] { readManifest(root / "w"); }).kind(), InputErrorKind::Io);
}

// The sources' own lights (a glTF's KHR_lights_punctual) round-trip through the manifest; a pack
// without lights writes no "lights" key, so its bytes are those of packs written before it.
TEST(Pack, ManifestLightsRoundTripAndBadOnesNameTheKey) {
  PackManifest m;
  m.spec = testSpec();
  m.source = "lit.gltf";
  EXPECT_EQ(pack_format::manifestText(m).find("\"lights\""), std::string::npos);
  SceneLight spot;
  spot.type = SceneLight::Type::Spot;
  spot.position = glm::dvec3(1.5, 2.25, -3.0);
  spot.direction = glm::vec3(0.0f, -1.0f, 0.0f);
  spot.color = glm::vec3(1.0f, 0.5f, 0.25f);
  spot.intensity = 42.0f;
  spot.range = 7.0f;
  spot.innerConeDegrees = 11.0f;
  spot.outerConeDegrees = 33.0f;
  spot.castsShadows = false;
  SceneLight sun;
  sun.direction = glm::normalize(glm::vec3(0.3f, -1.0f, 0.2f));
  m.lights = {spot, sun};
  const std::string text = pack_format::manifestText(m);
  const PackManifest back = pack_format::parseManifest(text, "manifest.json");
  ASSERT_EQ(back.lights.size(), 2u);
  const SceneLight& s = back.lights[0];
  EXPECT_EQ(s.type, SceneLight::Type::Spot);
  EXPECT_EQ(s.position, spot.position);
  EXPECT_EQ(s.direction, spot.direction);
  EXPECT_EQ(s.color, spot.color);
  EXPECT_EQ(s.intensity, spot.intensity);
  EXPECT_EQ(s.range, spot.range);
  EXPECT_EQ(s.innerConeDegrees, spot.innerConeDegrees);
  EXPECT_EQ(s.outerConeDegrees, spot.outerConeDegrees);
  EXPECT_EQ(s.castsShadows, false);
  EXPECT_EQ(back.lights[1].type, SceneLight::Type::Sun);
  EXPECT_NEAR(glm::length(back.lights[1].direction - sun.direction), 0.0f, 1e-6f);
  auto expectBad = [&](const std::string& from, const std::string& to, const std::string& key) {
    std::string t = text;
    const std::size_t at = t.find(from);
    ASSERT_NE(at, std::string::npos) << from;
    t.replace(at, from.size(), to);
    const InputError e = errorOf([&] { pack_format::parseManifest(t, "manifest.json"); });
    EXPECT_EQ(e.kind(), InputErrorKind::Malformed) << e.what();
    EXPECT_NE(std::string(e.what()).find(key), std::string::npos) << e.what();
  };
  expectBad("\"spot\"", "\"area\"", "lights[0].type");
  expectBad("\"intensity\": 42", "\"intensity\": -42", "lights[0]");
  expectBad("\"outerConeDegrees\": 33", "\"outerConeDegrees\": 3", "lights[0]");
}

TEST(Pack, DiskFullKeepsThePreviousPackAndLeavesNothing) {
  const fs::path root = test::scratchDir("pack-full");
  const PartitionSpec spec = testSpec();
  const std::vector<Tile> tiles = testTiles(spec);
  writePack(root / "w", {tiles[0]});
  const auto before = tree(root / "w");
  std::uint64_t total = 0;
  {
    writePack(root / "probe", tiles);
    for (const auto& [name, b] : tree(root / "probe")) total += b.size();
    fs::remove_all(root / "probe");
  }
  // Fail inside the first tile, inside a later tile, and while writing the manifest.
  for (std::uint64_t limit : {std::uint64_t(10), total / 2, total - 10}) {
    ::setenv("SDFSTREAM_FAIL_WRITE_AFTER_BYTES", std::to_string(limit).c_str(), 1);
    const InputError e = errorOf([&] { writePack(root / "w", tiles); });
    ::unsetenv("SDFSTREAM_FAIL_WRITE_AFTER_BYTES");
    EXPECT_EQ(e.kind(), InputErrorKind::Io) << limit << ": " << e.what();
    EXPECT_EQ(tree(root / "w"), before) << limit;
    expectOnlyEntry(root, "w");
  }
  // The same through writeWorld.
  World world = loadLod(root / "w", 0);
  ::setenv("SDFSTREAM_FAIL_WRITE_AFTER_BYTES", "100", 1);
  EXPECT_EQ(errorOf([&] { writeWorld(world, root / "w"); }).kind(), InputErrorKind::Io);
  ::unsetenv("SDFSTREAM_FAIL_WRITE_AFTER_BYTES");
  EXPECT_EQ(tree(root / "w"), before);
  expectOnlyEntry(root, "w");
}

TEST(Pack, DiskFullOnARealTinyFilesystem) {
  const fs::path root = test::scratchDir("pack-tmpfs");
  const PartitionSpec spec = testSpec();
  const std::vector<Tile> tiles = testTiles(spec);
  std::uint64_t small = 0, full = 0;
  writePack(root / "probe", {tiles[2]});
  for (const auto& [name, b] : tree(root / "probe")) small += b.size();
  writePack(root / "probe", tiles);
  for (const auto& [name, b] : tree(root / "probe")) full += b.size();
  fs::remove_all(root / "probe");
  // Room for the small pack (plus directory blocks), not for both packs at once.
  const std::string size = "size=" + std::to_string(small + full / 2 + 64 * 1024);
  if (::mount("tmpfs", root.c_str(), "tmpfs", 0, size.c_str()) != 0)
    GTEST_SKIP() << "cannot mount a tmpfs here (needs root); the injected failure test covers it";
  EXPECT_NO_THROW(writePack(root / "w", {tiles[2]}));
  const auto before = tree(root / "w");
  const InputError e = errorOf([&] { writePack(root / "w", tiles); });
  EXPECT_EQ(e.kind(), InputErrorKind::Io) << e.what();
  EXPECT_EQ(tree(root / "w"), before);
  expectOnlyEntry(root, "w");
  ::umount(root.c_str());
}

TEST(Pack, ShardsMergeToTheOneShotPack) {
  const fs::path root = test::scratchDir("pack-merge");
  const PartitionSpec spec = testSpec();
  const std::vector<Tile> tiles = testTiles(spec);
  writePack(root / "one", tiles);
  writePack(root / "s0", {tiles[0], tiles[2], tiles[4]});
  writePack(root / "s1", {tiles[1], tiles[3]});
  writePack(root / "s2", {});
  mergePacks({root / "s1", root / "s2", root / "s0"}, root / "merged");
  EXPECT_EQ(tree(root / "merged"), tree(root / "one"));
  EXPECT_EQ(verifyPack(root / "merged"), "");

  // Mismatched partition: named shard; duplicate tile: named tile. Output untouched.
  PartitionSpec other = spec;
  other.voxelSize = 0.5;
  writePack(root / "odd", {tiles[1]}, other);
  InputError e = errorOf([&] { mergePacks({root / "s0", root / "odd"}, root / "merged"); });
  EXPECT_EQ(e.kind(), InputErrorKind::Malformed);
  EXPECT_NE(std::string(e.what()).find("odd"), std::string::npos) << e.what();
  EXPECT_NE(std::string(e.what()).find("partition"), std::string::npos) << e.what();
  e = errorOf([&] { mergePacks({root / "s0", root / "one"}, root / "merged"); });
  EXPECT_EQ(e.kind(), InputErrorKind::Malformed);
  EXPECT_NE(std::string(e.what()).find("tiles/1_-1_0.tile"), std::string::npos) << e.what();
  EXPECT_EQ(tree(root / "merged"), tree(root / "one"));

  // A corrupt shard tile is not copied.
  std::string b = bytes(root / "s1/tiles/0_0_1.tile");
  b[b.size() - 1] = char(b.back() ^ 1);
  writeBytes(root / "s1/tiles/0_0_1.tile", b);
  e = errorOf([&] { mergePacks({root / "s0", root / "s1"}, root / "m2"); });
  EXPECT_EQ(e.kind(), InputErrorKind::Checksum);
  EXPECT_FALSE(fs::exists(root / "m2"));
}

// partition.h's rule, brute force: Chebyshev distance in bricks to the nearest brick within the
// tile and its one-brick ring, or to the first slot beyond the ring.
std::uint8_t bruteEmpty(const std::vector<glm::ivec3>& bricks, glm::ivec3 tile, int n,
                        glm::ivec3 local) {
  const glm::ivec3 p = tile * n + local;
  int best = 1 << 20;
  for (int a = 0; a < 3; ++a) best = std::min({best, local[a] + 2, n + 1 - local[a]});
  for (const glm::ivec3& b : bricks) {
    const glm::ivec3 l = b - tile * n;
    if (glm::any(glm::lessThan(l, glm::ivec3(-1))) || glm::any(glm::greaterThan(l, glm::ivec3(n))))
      continue;
    const glm::ivec3 d = glm::abs(b - p);
    best = std::min(best, std::max({d.x, d.y, d.z}));
  }
  return std::uint8_t(std::min(best, 255));
}

TEST(Pack, WriteWorldReadWorldRoundTripWithEmptyDistance) {
  const fs::path root = test::scratchDir("pack-world");
  World w;
  w.voxelSize = 0.1;
  w.origin = {-3, 0.5, 7};
  w.source = "sphere.gltf";
  std::mt19937 rng(11);
  std::vector<glm::ivec3> coords;
  for (int i = 0; i < 300; ++i)
    coords.push_back({int(rng() % 40) - 20, int(rng() % 12) - 6, int(rng() % 40) - 2});
  coords.push_back({16, 0, 0});  // beside a tile border
  std::sort(coords.begin(), coords.end(), brickCoordLess);
  coords.erase(std::unique(coords.begin(), coords.end()), coords.end());
  for (const glm::ivec3& c : coords) {
    Brick b;
    b.coord = c;
    b.distance.fill(std::uint16_t(rng()));
    b.albedo.fill(std::uint32_t(rng()));
    b.emission[3] = std::uint32_t(rng());
    w.bricks.push_back(b);
  }
  writeWorld(w, root / "w");
  EXPECT_TRUE(fs::exists(root / "w/manifest.json"));
  const World r = readWorld(root / "w");
  EXPECT_EQ(r.voxelSize, w.voxelSize);
  EXPECT_EQ(r.origin, w.origin);
  EXPECT_EQ(r.source, w.source);
  ASSERT_EQ(r.bricks.size(), w.bricks.size());
  for (std::size_t i = 0; i < w.bricks.size(); ++i)
    EXPECT_TRUE(sameBrick(r.bricks[i], w.bricks[i]));

  const PackManifest m = readManifest(root / "w");
  EXPECT_EQ(m.spec.lodCount, 1);
  EXPECT_EQ(m.boundsMin, w.worldMin());
  EXPECT_EQ(m.boundsMax, w.worldMax());
  const int n = m.spec.tileBricks(0);
  int mismatches = 0;
  for (const TileEntry& e : m.tiles) {
    const Tile t = readTile(root / "w", e, m.spec);
    for (int z = 0; z < n; ++z)
      for (int y = 0; y < n; ++y)
        for (int x = 0; x < n; ++x)
          mismatches += t.lods[0].emptyDistance[std::size_t(x + n * (y + n * z))] !=
                        bruteEmpty(coords, e.coord, n, {x, y, z});
  }
  EXPECT_EQ(mismatches, 0);

  writeWorld(w, root / "again");
  EXPECT_EQ(tree(root / "again"), tree(root / "w"));
  World empty;
  empty.voxelSize = 0.5;
  writeWorld(empty, root / "empty");
  EXPECT_TRUE(readWorld(root / "empty").bricks.empty());
}

}  // namespace
}  // namespace sdfstream
