// .vdb import against the source grids (shared data; skips when ../shared/data is absent).
#include <cmath>
#include <fstream>

#include <gtest/gtest.h>
#include <openvdb/io/File.h>
#include <openvdb/openvdb.h>

#include "core/error.h"
#include "tests/support/test_data.h"
#include "world/brick_sampler.h"
#include "world/import.h"
#include "world/vdb_import.h"
#include "world/world_io.h"

namespace sdfstream {
namespace {

namespace fs = std::filesystem;

openvdb::FloatGrid::Ptr firstLevelSet(const fs::path& path) {
  openvdb::initialize();
  openvdb::io::File file(path.string());
  file.open(false);
  openvdb::GridPtrVecPtr grids = file.getGrids();  // keep alive across the loop
  for (auto& g : *grids)
    if (auto f = openvdb::gridPtrCast<openvdb::FloatGrid>(g))
      if (f->getGridClass() == openvdb::GRID_LEVEL_SET) return f;
  return nullptr;
}

void expectMatchesSource(const char* name) {
  const fs::path path = test::sharedData() / "vdb" / name;
  World world = vdbToWorld(path, 0, {});
  openvdb::FloatGrid::Ptr src = firstLevelSet(path);
  ASSERT_TRUE(src);
  EXPECT_EQ(world.voxelSize, src->voxelSize()[0]);
  BrickSampler sampler(world);
  const double vs = world.voxelSize;
  std::size_t checked = 0;
  double worst = 0;
  for (auto it = src->cbeginValueOn(); it; ++it) {
    const double expected = double(*it) / vs;
    if (!it.isVoxelValue() || !(std::abs(expected) < layout::kNarrowBand)) continue;
    const openvdb::Vec3d p = src->indexToWorld(it.getCoord());
    std::optional<float> d = sampler.distanceVoxels({p.x(), p.y(), p.z()});
    ASSERT_TRUE(d) << "no brick at active voxel " << it.getCoord();
    worst = std::max(worst, std::abs(*d - expected));
    ASSERT_NEAR(*d, expected, 0.01) << "at " << it.getCoord();
    ++checked;
  }
  std::printf("[ vdb       ] %s: %zu bricks, %zu voxels checked, max |delta| %.5f voxel\n", name,
              world.bricks.size(), checked, worst);
  EXPECT_GT(checked, 1000u);
}

TEST(VdbImport, SphereMatchesSourceGrid) {
  SDFSTREAM_REQUIRE_SHARED_DATA("vdb/sphere.vdb");
  expectMatchesSource("sphere.vdb");
}

TEST(VdbImport, BunnyMatchesSourceGrid) {
  SDFSTREAM_REQUIRE_SHARED_DATA("vdb/bunny-levelset.vdb");
  expectMatchesSource("bunny-levelset.vdb");
}

void expectImportFails(const fs::path& input, InputErrorKind kind, const char* mention) {
  const fs::path out = test::scratchDir("vdb-fail") / "out";
  try {
    importToDirectory(input, out, {});
    ADD_FAILURE() << "import of " << input << " succeeded";
  } catch (const InputError& e) {
    EXPECT_EQ(e.kind(), kind) << e.what();
    EXPECT_NE(std::string(e.what()).find(mention), std::string::npos) << e.what();
    std::printf("[ vdb       ] expected error: %s\n", e.what());
  }
  EXPECT_FALSE(fs::exists(out));
  for (const auto& entry : fs::directory_iterator(out.parent_path()))
    ADD_FAILURE() << "left behind: " << entry.path();
}

TEST(VdbImport, FogVolumeIsNotALevelSet) {
  SDFSTREAM_REQUIRE_SHARED_DATA("vdb/smoke.vdb");
  expectImportFails(test::sharedData() / "vdb/smoke.vdb", InputErrorKind::NotLevelSet, "fog");
}

TEST(VdbImport, PointsAreNotALevelSet) {
  SDFSTREAM_REQUIRE_SHARED_DATA("vdb/points.vdb");
  expectImportFails(test::sharedData() / "vdb/points.vdb", InputErrorKind::NotLevelSet,
                    "point data");
}

TEST(VdbImport, TruncatedFile) {
  SDFSTREAM_REQUIRE_SHARED_DATA("vdb/sphere.vdb");
  const fs::path dir = test::scratchDir("vdb-truncated");
  std::ifstream in(test::sharedData() / "vdb/sphere.vdb", std::ios::binary);
  std::vector<char> b{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  for (double fraction : {0.999, 0.9, 0.5, 0.01, 0.0001}) {
    const fs::path cut = dir / ("sphere-" + std::to_string(int(fraction * 10000)) + ".vdb");
    std::ofstream(cut, std::ios::binary).write(b.data(), std::streamsize(b.size() * fraction));
    expectImportFails(cut, InputErrorKind::Truncated, "sphere-");
  }
}

// A grid's name comes from the file; one holding a newline made the NotLevelSet error two lines,
// which breaks fuzz/vdb_fuzz.cpp's one-line contract. It is now quoted printable.
TEST(VdbImport, GridNameWithNewlineKeepsTheErrorOneLine) {
  openvdb::initialize();
  auto fog = openvdb::FloatGrid::create(0.0f);
  fog->setName("den\nsity");
  fog->setGridClass(openvdb::GRID_FOG_VOLUME);
  fog->tree().setValue(openvdb::Coord(1, 2, 3), 0.5f);
  const fs::path path = test::scratchDir("vdb-grid-name") / "fog.vdb";
  openvdb::io::File(path.string()).write({fog});
  try {
    vdbToWorld(path, 0, {});
    ADD_FAILURE() << "a fog volume imported";
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_EQ(e.kind(), InputErrorKind::NotLevelSet) << what;
    EXPECT_EQ(what.find('\n'), std::string::npos) << what;
    EXPECT_NE(what.find("'den\\x0asity'"), std::string::npos) << what;
    EXPECT_EQ(what.rfind(path.string(), 0), 0u) << what;
  }
}

TEST(VdbImport, VoxelSizeOverrideResamples) {
  SDFSTREAM_REQUIRE_SHARED_DATA("vdb/sphere.vdb");
  const fs::path path = test::sharedData() / "vdb/sphere.vdb";
  World own = vdbToWorld(path, 0, {});
  World coarse = vdbToWorld(path, own.voxelSize * 2, {});
  EXPECT_EQ(coarse.voxelSize, own.voxelSize * 2);
  EXPECT_EQ(coarse.origin, glm::dvec3(0.0));
  EXPECT_LT(coarse.bricks.size(), own.bricks.size());
  // The coarse zero set agrees with the fine one: sample fine surface points in the coarse world.
  BrickSampler fine(own), c(coarse);
  int checked = 0;
  for (const Brick& b : own.bricks)
    for (int z = 0; z < 8; ++z)
      for (int x = 0; x < 8; ++x) {
        glm::dvec3 p = own.origin + glm::dvec3(b.coord * 8 + glm::ivec3(x, 4, z)) * own.voxelSize;
        auto df = fine.distanceVoxels(p);
        if (!df || std::abs(*df) > 0.5f) continue;
        auto dc = c.distanceVoxels(p);
        ASSERT_TRUE(dc);
        EXPECT_NEAR(*dc * 2.0, *df, 1.0);  // coarse voxels are twice as big
        ++checked;
      }
  EXPECT_GT(checked, 100);
}

}  // namespace
}  // namespace sdfstream
