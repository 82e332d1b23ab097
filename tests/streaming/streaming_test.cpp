// Streaming invariants: scrolling equals rebuilding, the frame never waits on I/O,
// failures are reported (never turned into empty space), budgets hold, far-from-origin worlds
// stream exactly like ones near the origin.
#include <gtest/gtest.h>

#include <cstdio>
#include <random>

#include "streaming/cascade_stack.h"
#include "tests/streaming/memory_tile_store.h"

namespace sdfstream {
namespace {

PartitionSpec testSpec() { return test::smallTestSpec(); }
StreamingOptions testOptions() { return test::smallTestOptions(); }

// Updates until every page is settled (each round lets the loader finish what was requested).
void settle(CascadeStack& stack, TileLoader& loader, const glm::dvec3& camera) {
  for (int round = 0; round < 200; ++round) {
    stack.update(camera);
    if (stack.settled()) return;
    loader.waitIdle();
  }
  FAIL() << "cascades did not settle";
}

// Compares two stacks page by page: same kind of entry, same bound, same brick bytes.
void expectSameContents(const CascadeStack& a, const CascadeStack& b) {
  const std::size_t words = layout::kBrickDistanceWords, mats = layout::kBrickMaterialCount;
  for (int c = 0; c < a.cascadeCount(); ++c) {
    ASSERT_EQ(a.originBrick(c), b.originBrick(c)) << "cascade " << c;
    auto pa = a.pageTable(c), pb = b.pageTable(c);
    for (std::size_t i = 0; i < pa.size(); ++i) {
      bool ra = pa[i] & layout::kPageResidentBit, rb = pb[i] & layout::kPageResidentBit;
      ASSERT_EQ(ra, rb) << "cascade " << c << " page " << i;
      if (!ra) {
        ASSERT_EQ(pa[i], pb[i]) << "cascade " << c << " page " << i;
        continue;
      }
      std::size_t sa = pa[i] & layout::kPagePayloadMask, sb = pb[i] & layout::kPagePayloadMask;
      ASSERT_TRUE(std::equal(a.atlasDistance().begin() + sa * words,
                             a.atlasDistance().begin() + (sa + 1) * words,
                             b.atlasDistance().begin() + sb * words));
      ASSERT_TRUE(std::equal(a.atlasAlbedo().begin() + sa * mats,
                             a.atlasAlbedo().begin() + (sa + 1) * mats,
                             b.atlasAlbedo().begin() + sb * mats));
      ASSERT_TRUE(std::equal(a.atlasEmission().begin() + sa * mats,
                             a.atlasEmission().begin() + (sa + 1) * mats,
                             b.atlasEmission().begin() + sb * mats));
    }
  }
}

TEST(Streaming, RandomCameraPathsEqualAFreshBuild) {
  test::MemoryTileStore store(testSpec(), 12);
  TileLoader loader(store);
  CascadeStack stack(store, loader, testOptions());
  std::mt19937 rng(2024);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  glm::dvec3 camera(3.0, -2.0, 5.0);
  settle(stack, loader, camera);
  const double brick = 8.0 * testSpec().voxelSize;
  for (int step = 0; step < 40; ++step) {
    int kind = int(rng() % 10);
    if (kind == 0) {  // teleport
      camera = glm::dvec3(u(rng), u(rng), u(rng)) * 300.0;
    } else {  // 0.3–3 bricks along a random (often diagonal) direction, sometimes reversing
      glm::dvec3 dir = glm::normalize(glm::dvec3(u(rng), u(rng), u(rng)));
      double len = (0.3 + 2.7 * (u(rng) * 0.5 + 0.5)) * brick;
      camera += dir * len;
      if (kind == 1) camera -= dir * len * 2.0;
    }
    // Sometimes move again before the previous move settled.
    if (step % 3 == 0) stack.update(camera);
    else settle(stack, loader, camera);
  }
  settle(stack, loader, camera);

  TileLoader freshLoader(store);
  CascadeStack fresh(store, freshLoader, testOptions());
  settle(fresh, freshLoader, camera);
  std::uint32_t resident = 0;
  for (int c = 0; c < fresh.cascadeCount(); ++c) resident += fresh.cascadeImage(c).residentBricks;
  ASSERT_GT(resident, 100u) << "the comparison must cover real bricks";
  expectSameContents(stack, fresh);
}

TEST(Streaming, TheFrameNeverWaitsForDisk) {
  test::MemoryTileStore store(testSpec(), 6);
  store.closeGate();  // every load() blocks until the gate opens
  TileLoader loader(store);
  CascadeStack stack(store, loader, testOptions());
  StreamFrameStats first = stack.update(glm::dvec3(0.0));  // must return with loads blocked
  EXPECT_GT(first.missingPages, 0u);
  EXPECT_EQ(first.bytesUploaded, 0u);
  for (int i = 0; i < 5; ++i) EXPECT_GT(stack.update(glm::dvec3(0.0)).missingPages, 0u);
  store.openGate();
  settle(stack, loader, glm::dvec3(0.0));
  EXPECT_EQ(stack.update(glm::dvec3(0.0)).missingPages, 0u);
}

TEST(Streaming, FailingTileIsReportedNotTreatedAsEmpty) {
  test::MemoryTileStore store(testSpec(), 6);
  glm::ivec3 bad(0, 0, 0);
  ASSERT_TRUE(store.hasTile(bad) || true);
  // Pick a tile that exists near the camera.
  for (int x = -2; x <= 2 && !store.hasTile(bad); ++x) bad = glm::ivec3(x, 0, 0);
  ASSERT_TRUE(store.hasTile(bad));
  store.failing.insert({bad.x, bad.y, bad.z});
  LoaderOptions lo;
  lo.backoffMilliseconds = 1.0;
  TileLoader loader(store, lo);
  CascadeStack stack(store, loader, testOptions());
  StreamFrameStats s;
  for (int i = 0; i < 50; ++i) {
    s = stack.update(glm::dvec3(0.0));
    loader.waitIdle();
  }
  EXPECT_TRUE(loader.failed(TileKey{bad, 0}));
  EXPECT_GT(s.failedPages, 0u);
  EXPECT_GT(s.missingPages, 0u);  // still missing, not silently empty
  LoaderStats ls = loader.takeStats();
  // One failure per LOD of the bad tile that a cascade asked for, each after maxAttempts tries.
  EXPECT_GE(ls.failures, 1u);
  EXPECT_LE(ls.failures, std::uint64_t(testSpec().lodCount));
  EXPECT_EQ(ls.retries, ls.failures * std::uint64_t(lo.maxAttempts - 1));
}

TEST(Streaming, UploadBudgetIsRespectedPerFrame) {
  test::MemoryTileStore store(testSpec(), 8);
  TileLoader loader(store);
  StreamingOptions o = testOptions();
  o.uploadBytesPerFrame = 20 * 4 * (layout::kBrickDistanceWords + 2 * layout::kBrickMaterialCount);
  CascadeStack stack(store, loader, o);
  int frames = 0;
  while (!stack.settled() && frames < 2000) {
    StreamFrameStats s = stack.update(glm::dvec3(1.0, 2.0, 3.0));
    EXPECT_LE(s.bytesUploaded, o.uploadBytesPerFrame);
    loader.waitIdle();
    ++frames;
  }
  EXPECT_TRUE(stack.settled());
  EXPECT_GT(frames, 2);  // the budget actually spread the work over frames
}

TEST(Streaming, RequestsThatLeftTheWindowAreCancelled) {
  test::MemoryTileStore store(testSpec(), 30);
  store.closeGate();
  LoaderOptions lo;
  lo.threads = 1;
  TileLoader loader(store, lo);
  CascadeStack stack(store, loader, testOptions());
  stack.update(glm::dvec3(0.0));
  stack.update(glm::dvec3(900.0, 0.0, 0.0));  // teleport: the old window's requests are stale
  EXPECT_GT(loader.takeStats().cancelled, 0u);
  store.openGate();
}

TEST(Streaming, FarFromTheOriginStreamsExactlyLikeNearIt) {
  // The same world shifted by 100 km: tile coordinates are integers, positions doubles, and the
  // cascades hold only integer brick coordinates, so both must produce identical contents.
  PartitionSpec spec = testSpec();
  const int shiftTiles = 100000 / spec.tileVoxels;  // 100 km at 1 m voxels
  test::MemoryTileStore nearStore(spec, 6), farStore(spec, 6, glm::ivec3(shiftTiles, 0, shiftTiles));
  TileLoader nearLoader(nearStore), farLoader(farStore);
  CascadeStack nearStack(nearStore, nearLoader, testOptions()),
      farStack(farStore, farLoader, testOptions());
  glm::dvec3 nearCam(5.3, 1.7, -2.2);
  glm::dvec3 farCam = nearCam + glm::dvec3(shiftTiles * spec.tileSizeMeters(), 0.0,
                                           shiftTiles * spec.tileSizeMeters());
  settle(nearStack, nearLoader, nearCam);
  settle(farStack, farLoader, farCam);
  for (int c = 0; c < nearStack.cascadeCount(); ++c) {
    CascadeImage a = nearStack.cascadeImage(c), b = farStack.cascadeImage(c);
    EXPECT_EQ(a.toCascade(nearCam), b.toCascade(farCam)) << "cascade-relative camera differs";
    EXPECT_EQ(a.residentBricks, b.residentBricks);
  }
  // Page contents equal once the toroidal shift (multiple of 16 bricks? not necessarily) is
  // accounted for: compare page by page in window order.
  for (int c = 0; c < nearStack.cascadeCount(); ++c) {
    CascadeImage a = nearStack.cascadeImage(c), b = farStack.cascadeImage(c);
    for (int z = 0; z < 16; ++z)
      for (int y = 0; y < 16; ++y)
        for (int x = 0; x < 16; ++x) {
          std::uint32_t ea = a.pageTable[a.pageIndex({x, y, z})];
          std::uint32_t eb = b.pageTable[b.pageIndex({x, y, z})];
          ASSERT_EQ(bool(ea & layout::kPageResidentBit), bool(eb & layout::kPageResidentBit));
          if (!(ea & layout::kPageResidentBit)) {
            ASSERT_EQ(ea, eb);
            continue;
          }
          std::size_t sa = ea & layout::kPagePayloadMask, sb = eb & layout::kPagePayloadMask;
          ASSERT_EQ(a.albedoAtlas[sa * layout::kBrickMaterialCount],
                    b.albedoAtlas[sb * layout::kBrickMaterialCount]);
          ASSERT_EQ(a.distanceAtlas[sa * layout::kBrickDistanceWords + 7],
                    b.distanceAtlas[sb * layout::kBrickDistanceWords + 7]);
        }
  }
}

}  // namespace
}  // namespace sdfstream

namespace sdfstream {
namespace {

TEST(Streaming, PagesInFrontOfTheCameraAreFilledFirst) {
  test::MemoryTileStore store(testSpec(), 8);
  TileLoader loader(store);
  // Warm the cache so only the upload budget limits the first frame.
  {
    CascadeStack warm(store, loader, testOptions());
    settle(warm, loader, glm::dvec3(0.0));
  }
  StreamingOptions o = testOptions();
  o.uploadBytesPerFrame = 40 * 4 * (layout::kBrickDistanceWords + 2 * layout::kBrickMaterialCount);
  CascadeStack stack(store, loader, o);
  stack.update(glm::dvec3(0.0), glm::dvec3(1.0, 0.0, 0.0));
  // Among cascade 0's resident pages, those in front (+x) must outnumber those behind.
  int front = 0, back = 0;
  CascadeImage img = stack.cascadeImage(0);
  for (int z = 0; z < 16; ++z)
    for (int y = 0; y < 16; ++y)
      for (int x = 0; x < 16; ++x)
        if (img.pageTable[img.pageIndex({x, y, z})] & layout::kPageResidentBit)
          (x >= 8 ? front : back)++;
  EXPECT_GT(front, 0);
  EXPECT_GT(front, 2 * back) << "front " << front << " back " << back;
}

}  // namespace
}  // namespace sdfstream
