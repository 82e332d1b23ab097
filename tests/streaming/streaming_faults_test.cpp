// Streaming under faults: a tile deleted or corrupted while flying, injected
// I/O latency, an atlas smaller than one cascade. Each must degrade gracefully with counted misses:
// no crash, no hang, and never a page silently turned into empty space.
#include <gtest/gtest.h>

#include <fstream>

#include "streaming/cascade_stack.h"
#include "streaming/pack_store.h"
#include "tests/streaming/memory_tile_store.h"
#include "tests/support/test_data.h"
#include "world/pack.h"

namespace sdfstream {
namespace {

PartitionSpec faultSpec() { return test::smallTestSpec(); }
StreamingOptions faultOptions() { return test::smallTestOptions(); }

// Writes the procedural world of MemoryTileStore into a real pack on disk.
std::filesystem::path writeTestPack(const std::string& name) {
  test::MemoryTileStore source(faultSpec(), 4);
  auto dir = test::scratchDir(name) / "pack";
  PackWriter writer(dir, faultSpec());
  for (int z = -4; z <= 4; ++z)
    for (int y = -4; y <= 4; ++y)
      for (int x = -4; x <= 4; ++x)
        if (source.hasTile({x, y, z})) writer.addTile(*source.load({x, y, z}, 0, nullptr));
  writer.commit(glm::dvec3(-128.0), glm::dvec3(160.0), "memory", {"test"});
  return dir;
}

// The pages of `tile` in cascade `c` that the stack currently holds.
std::vector<std::uint32_t> pagesOfTile(const CascadeStack& stack, int c, glm::ivec3 tile,
                                       const PartitionSpec& spec) {
  std::vector<std::uint32_t> out;
  const int n = spec.tileBricks(c);
  CascadeImage img = stack.cascadeImage(c);
  for (int z = 0; z < 16; ++z)
    for (int y = 0; y < 16; ++y)
      for (int x = 0; x < 16; ++x) {
        glm::ivec3 b = img.originBrick + glm::ivec3(x, y, z);
        glm::ivec3 t(int(std::floor(double(b.x) / n)), int(std::floor(double(b.y) / n)),
                     int(std::floor(double(b.z) / n)));
        if (t == tile) out.push_back(img.pageTable[img.pageIndex({x, y, z})]);
      }
  return out;
}

TEST(StreamingFaults, TilesDeletedOrCorruptedWhileFlyingStayMissingAndAreReported) {
  auto dir = writeTestPack("faults-pack");
  PackTileStore store(dir);
  LoaderOptions lo;
  lo.cacheBytes = 1;  // nothing stays cached: every scroll back re-reads from disk
  lo.backoffMilliseconds = 1.0;
  TileLoader loader(store, lo);
  CascadeStack stack(store, loader, faultOptions());
  // Fly out, damage two tiles behind the camera, fly back over them.
  glm::dvec3 camera(0.0);
  for (int f = 0; f < 30; ++f) {
    stack.update(camera);
    loader.waitIdle();
  }
  const PackManifest& m = store.manifest();
  ASSERT_GE(m.tiles.size(), 2u);
  const TileEntry* deleted = nullptr;
  const TileEntry* corrupted = nullptr;
  for (const TileEntry& e : m.tiles) {
    if (e.coord == glm::ivec3(0, 0, 0) || e.coord == glm::ivec3(-1, -1, -1) || e.bricksPerLod[0] == 0)
      continue;
    if (std::abs(e.coord.x) > 1 || std::abs(e.coord.y) > 1 || std::abs(e.coord.z) > 1) continue;
    if (!deleted) deleted = &e;
    else if (!corrupted) corrupted = &e;
  }
  ASSERT_TRUE(deleted && corrupted);
  for (int f = 0; f < 20; ++f) {  // away from them, so their pages leave cascade 0
    stack.update(camera + glm::dvec3(400.0, 0.0, 0.0));
    loader.waitIdle();
  }
  std::filesystem::remove(dir / deleted->file);
  {
    std::fstream f(dir / corrupted->file, std::ios::in | std::ios::out | std::ios::binary);
    f.seekp(std::streamoff(200));  // inside the LOD-0 section (the header is 168 bytes for 3 LODs)
    char c = 0x5a;
    f.write(&c, 1);
  }
  StreamFrameStats s;
  for (int f = 0; f < 80; ++f) {
    s = stack.update(camera);
    loader.waitIdle();
  }
  EXPECT_TRUE(loader.failed(TileKey{deleted->coord, 0}));
  EXPECT_TRUE(loader.failed(TileKey{corrupted->coord, 0}));
  EXPECT_GT(s.failedPages, 0u);
  EXPECT_GT(s.missingPages, 0u);
  for (glm::ivec3 bad : {deleted->coord, corrupted->coord})
    for (std::uint32_t e : pagesOfTile(stack, 0, bad, store.spec()))
      EXPECT_EQ(e, layout::kPageMissing) << "a failed tile's page must stay missing";
}

TEST(StreamingFaults, InjectedLatencyIsAbsorbedWithCountedMisses) {
  test::MemoryTileStore store(faultSpec(), 2);
  store.latencyMs = 200;
  LoaderOptions lo;
  lo.threads = 8;  // latency-bound reads overlap, as on a real disk queue
  TileLoader loader(store, lo);
  CascadeStack stack(store, loader, faultOptions());
  StreamFrameStats first = stack.update(glm::dvec3(0.0));
  EXPECT_GT(first.missingPages, 0u);  // the frame went on without the 200 ms reads
  int frames = 1;
  while (!stack.settled() && frames < 1000) {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
    stack.update(glm::dvec3(0.0));
    ++frames;
  }
  EXPECT_TRUE(stack.settled()) << "latency delays residency, it must not prevent it";
  EXPECT_GT(frames, 5);
  LoaderStats ls = loader.takeStats();
  ASSERT_FALSE(ls.latenciesMs.empty());
  EXPECT_GE(*std::min_element(ls.latenciesMs.begin(), ls.latenciesMs.end()), 190.0);
}

TEST(StreamingFaults, AnAtlasSmallerThanOneCascadeDegradesWithCountedMisses) {
  test::MemoryTileStore store(faultSpec(), 6);
  TileLoader loader(store);
  StreamingOptions o = faultOptions();
  o.atlasSlots = 16;
  CascadeStack stack(store, loader, o);
  StreamFrameStats s;
  for (int f = 0; f < 30; ++f) {
    s = stack.update(glm::dvec3(3.0 * f, 0.0, 0.0));
    loader.waitIdle();
  }
  EXPECT_EQ(s.atlasSlotsUsed, 16u);
  EXPECT_GT(s.atlasFullPages, 0u);
  EXPECT_GT(s.missingPages, 0u);
  std::uint32_t resident = 0;
  for (const auto& c : s.cascades) resident += c.residentBricks;
  EXPECT_LE(resident, 16u);
}

}  // namespace
}  // namespace sdfstream
