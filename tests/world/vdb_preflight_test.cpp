// The .vdb preflight (world/vdb_preflight.h): every file OpenVDB writes passes it and reads back
// the same, and each dishonest length OpenVDB would trust (found by fuzz/vdb_fuzz.cpp, or read
// off OpenVDB's readers) is refused with the right kind before OpenVDB allocates anything.
#include <cstring>
#include <limits>
#include <fstream>
#include <sstream>

#include <gtest/gtest.h>
#include <openvdb/io/File.h>
#include <openvdb/io/Stream.h>
#include <openvdb/openvdb.h>
#include <openvdb/tools/LevelSetSphere.h>

#include "core/error.h"
#include "tests/support/test_data.h"
#include "world/level_set_bricks.h"
#include "world/vdb_import.h"
#include "world/vdb_preflight.h"

namespace sdfstream {
namespace {

namespace fs = std::filesystem;

openvdb::FloatGrid::Ptr sphere() {
  openvdb::initialize();
  auto grid = openvdb::tools::createLevelSetSphere<openvdb::FloatGrid>(
      /*radius=*/6.0f, openvdb::Vec3f(1.0f, 2.0f, 3.0f), /*voxelSize=*/0.5f, /*halfWidth=*/3.0f);
  grid->setName("surface");
  return grid;
}

std::string readBytes(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

void writeBytes(const fs::path& path, const std::string& bytes) {
  std::ofstream(path, std::ios::binary).write(bytes.data(), std::streamsize(bytes.size()));
}

// One scratch folder for the whole file (scratchDir empties the folder it names).
const fs::path& scratch() {
  static const fs::path dir = test::scratchDir("vdb-preflight");
  return dir;
}

std::string writeVdb(const std::string& name, const openvdb::GridPtrVec& grids,
                     std::uint32_t compression) {
  const fs::path path = scratch() / name;
  openvdb::io::File file(path.string());
  file.setCompression(compression);
  file.write(grids);
  file.close();
  return readBytes(path);
}

template <typename T>
T load(const std::string& bytes, std::size_t at) {
  T v;
  std::memcpy(&v, bytes.data() + at, sizeof v);
  return v;
}
template <typename T>
void store(std::string& bytes, std::size_t at, T v) {
  std::memcpy(bytes.data() + at, &v, sizeof v);
}

// Position of the first byte after the length-prefixed string `s` in the file.
std::size_t after(const std::string& bytes, const std::string& s) {
  const std::size_t at = bytes.find(s);
  EXPECT_NE(at, std::string::npos) << s;
  EXPECT_EQ(load<std::uint32_t>(bytes, at - 4), s.size()) << s;
  return at + s.size();
}

InputError preflightError(const std::string& bytes) {
  try {
    preflightVdb(bytes, "hostile.vdb");
  } catch (const InputError& e) {
    std::printf("[ preflight ] %s\n", e.what());
    return e;
  }
  ADD_FAILURE() << "the preflight accepted the file";
  return InputError(InputErrorKind::Io, "", "");
}

// Every compression OpenVDB writes, full and half floats: the preflight's walk ends exactly
// where each grid's descriptor says (it checks that itself), and the grid reads back unchanged.
TEST(VdbPreflight, EveryCodecAndHalfFloatPassAndReadBackTheSame) {
  using namespace openvdb::io;
  const openvdb::FloatGrid::Ptr source = sphere();
  int files = 0;
  for (std::uint32_t compression : std::initializer_list<std::uint32_t>{
           COMPRESS_NONE, COMPRESS_ZIP, COMPRESS_BLOSC, COMPRESS_ACTIVE_MASK,
        COMPRESS_ZIP | COMPRESS_ACTIVE_MASK, COMPRESS_BLOSC | COMPRESS_ACTIVE_MASK}) {
    for (bool half : {false, true}) {
      source->setSaveFloatAsHalf(half);
      const std::string name = "codec-" + std::to_string(compression) + (half ? "-half" : "");
      const std::string bytes = writeVdb(name + ".vdb", {source}, compression);
      const VdbPreflight checked = preflightVdb(bytes, name);
      EXPECT_EQ(checked.floatGridCount(), 1u) << name;
      EXPECT_TRUE(checked.others.empty()) << name;

      const LevelSetFile f = readLevelSetGrids(scratch() / (name + ".vdb"));
      ASSERT_EQ(f.grids.size(), 1u) << name;
      const openvdb::FloatGrid& read = *f.grids[0];
      EXPECT_EQ(read.activeVoxelCount(), source->activeVoxelCount()) << name;
      double worst = 0;
      for (auto it = source->cbeginValueOn(); it; ++it)
        worst = std::max(worst, double(std::abs(read.tree().getValue(it.getCoord()) - *it)));
      EXPECT_LE(worst, half ? 2e-3 : 0.0) << name;
      ++files;
    }
  }
  source->setSaveFloatAsHalf(false);
  EXPECT_EQ(files, 12);
}

// Grids of other types are cut out before OpenVDB reads anything, and still named.
TEST(VdbPreflight, OtherGridTypesAreCutOutAndNamed) {
  auto velocity = openvdb::Vec3SGrid::create();
  velocity->setName("velocity");
  velocity->tree().setValue(openvdb::Coord(1, 2, 3), openvdb::Vec3s(1, 0, 0));
  auto ids = openvdb::Int32Grid::create();
  ids->setName("ids");
  ids->setGridClass(openvdb::GRID_STAGGERED);
  ids->tree().setValue(openvdb::Coord(4, 5, 6), 7);
  const std::string bytes =
      writeVdb("mixed.vdb", {velocity, sphere(), ids}, openvdb::io::COMPRESS_BLOSC);
  const VdbPreflight checked = preflightVdb(bytes, "mixed.vdb");
  EXPECT_EQ(checked.floatGridCount(), 1u);
  ASSERT_EQ(checked.others.size(), 2u);
  EXPECT_EQ(checked.order, (std::vector<int>{0, -1, 1}));
  EXPECT_EQ(checked.others[0].description, "grid 'velocity' (vec3s)");
  EXPECT_EQ(checked.others[1].description, "staggered 'ids' (int32)");
  EXPECT_LT(checked.floatGridBytes.size(), bytes.size());

  const LevelSetFile f = readLevelSetGrids(scratch() / "mixed.vdb");
  ASSERT_EQ(f.grids.size(), 1u);
  EXPECT_EQ(f.grids[0]->getName(), "surface");
  EXPECT_EQ(f.skipped, (std::vector<std::string>{"'velocity' (vec3s grid)", "'ids' (staggered)"}));
}

// A grid sharing another's tree is written as an instance: its descriptor names the parent and
// its data is only metadata and a transform. Both read back with the same tree.
TEST(VdbPreflight, InstancedGridsPassAndShareTheirTree) {
  const openvdb::FloatGrid::Ptr surface = sphere();
  openvdb::GridBase::Ptr copy = surface->copyGrid();  // shares the tree
  copy->setName("copy");
  const std::string bytes = writeVdb("instanced.vdb", {surface, copy}, openvdb::io::COMPRESS_BLOSC);
  ASSERT_NE(bytes.find("surface"), std::string::npos);
  const VdbPreflight checked = preflightVdb(bytes, "instanced.vdb");
  EXPECT_EQ(checked.floatGridCount(), 2u);
  const LevelSetFile f = readLevelSetGrids(scratch() / "instanced.vdb");
  ASSERT_EQ(f.grids.size(), 2u);
  EXPECT_EQ(f.grids[1]->activeVoxelCount(), surface->activeVoxelCount());
}

// A file written as a stream has no grid offsets: float grids are walked to their end, any other
// grid cannot be skipped and is refused by name.
TEST(VdbPreflight, StreamWrittenFilesReadTheirFloatGridsAndRefuseOthers) {
  std::ostringstream floatOnly(std::ios::binary);
  openvdb::io::Stream(floatOnly).write({sphere()});
  EXPECT_EQ(preflightVdb(floatOnly.str(), "stream.vdb").floatGridCount(), 1u);

  auto velocity = openvdb::Vec3SGrid::create();
  velocity->setName("velocity");
  std::ostringstream mixed(std::ios::binary);
  openvdb::io::Stream(mixed).write({velocity, sphere()});
  const InputError e = preflightError(mixed.str());
  EXPECT_EQ(e.kind(), InputErrorKind::Unsupported);
  EXPECT_NE(std::string(e.what()).find("'velocity'"), std::string::npos);
}

// A fuzz finding: a 2.6 GB transform type name in a 1 KB file. OpenVDB's readString allocates
// (and fills) the declared length before reading.
TEST(VdbPreflight, ATransformNameLongerThanTheFileIsTruncated) {
  std::string bytes = writeVdb("name.vdb", {sphere()}, openvdb::io::COMPRESS_BLOSC);
  store<std::uint32_t>(bytes, after(bytes, "UniformScaleMap") - 15 - 4, 2'600'000'000u);
  const InputError e = preflightError(bytes);
  EXPECT_EQ(e.kind(), InputErrorKind::Truncated);
  EXPECT_NE(std::string(e.what()).find("transform type name"), std::string::npos);
  EXPECT_NE(std::string(e.what()).find("'surface'"), std::string::npos);
}

TEST(VdbPreflight, CountsBeyondTheFileAreRefusedBeforeAnyLoop) {
  const std::string good = writeVdb("counts.vdb", {sphere()}, openvdb::io::COMPRESS_ZIP);
  // The root's child count: OpenVDB loops over it without checking for the end of the stream,
  // allocating a 32³ node each time. It follows the transform (120 bytes), the tree's buffer
  // count, the background and the tile count.
  std::string children = good;
  store<std::uint32_t>(children, after(children, "UniformScaleMap") + 120 + 12, 4'000'000'000u);
  EXPECT_EQ(preflightError(children).kind(), InputErrorKind::Truncated);

  // The grid count, which io::Stream reserves descriptors for: after the header (57 bytes) and
  // the empty file metadata (a count of 0).
  std::string grids = good;
  ASSERT_EQ(load<std::uint32_t>(grids, 57), 0u);
  ASSERT_EQ(load<std::int32_t>(grids, 61), 1);
  store<std::int32_t>(grids, 61, 0x7fffffff);
  EXPECT_EQ(preflightError(grids).kind(), InputErrorKind::Truncated);
  store<std::int32_t>(grids, 61, -1);
  EXPECT_EQ(preflightError(grids).kind(), InputErrorKind::Malformed);

  // A grid whose descriptor places its end beyond the file.
  std::string end = good;
  const std::size_t offsets = after(end, "Tree_float_5_4_3") + 4;  // past the empty parent name
  store<std::int64_t>(end, offsets + 16, std::int64_t(end.size()) + 1000);
  EXPECT_EQ(preflightError(end).kind(), InputErrorKind::Truncated);
}

// The first leaf buffer's chunk size (blosc, no mask compression: 512 floats per leaf; OpenVDB
// never zips level sets). OpenVDB allocates a positive size before reading, and reads a negative
// (uncompressed) one into the leaf's 2 KiB buffer before comparing it with the buffer's length.
TEST(VdbPreflight, DishonestChunkSizesAreRefused) {
  const std::string good = writeVdb("chunks.vdb", {sphere()}, openvdb::io::COMPRESS_BLOSC);
  const std::size_t offsets = after(good, "Tree_float_5_4_3") + 4;
  const auto blockPos = static_cast<std::size_t>(load<std::int64_t>(good, offsets + 8));
  const auto metadata = static_cast<unsigned char>(good[blockPos + 64]);
  std::size_t chunk = blockPos + 64 + 1;
  if (metadata == 2 || metadata == 4 || metadata == 5) chunk += 4;
  if (metadata == 5) chunk += 4;
  if (metadata >= 3 && metadata <= 5) chunk += 64;
  const auto size = load<std::int64_t>(good, chunk);
  ASSERT_GT(size, 0);
  ASSERT_LE(size, 2048);

  std::string huge = good;
  store<std::int64_t>(huge, chunk, std::int64_t(1) << 40);
  EXPECT_EQ(preflightError(huge).kind(), InputErrorKind::Truncated);

  std::string overrun = good;
  store<std::int64_t>(overrun, chunk, -(std::int64_t(1) << 20));
  const InputError e = preflightError(overrun);
  EXPECT_EQ(e.kind(), InputErrorKind::Malformed);
  EXPECT_NE(std::string(e.what()).find("uncompressed chunk of 1048576 bytes where 2048"),
            std::string::npos);

  // blosc decompresses by the sizes in the chunk's own header: they must agree with OpenVDB's.
  std::string header = good;
  store<std::uint32_t>(header, chunk + 8 + 4, 1u << 30);
  EXPECT_EQ(preflightError(header).kind(), InputErrorKind::Malformed);

  std::string lowest = good;
  store<std::int64_t>(lowest, chunk, std::numeric_limits<std::int64_t>::min());
  EXPECT_EQ(preflightError(lowest).kind(), InputErrorKind::Malformed);
}

TEST(VdbPreflight, HeaderAndMetadataLies) {
  const std::string good = writeVdb("header.vdb", {sphere()}, openvdb::io::COMPRESS_BLOSC);
  std::string version = good;
  store<std::uint32_t>(version, 8, 300);
  EXPECT_EQ(preflightError(version).kind(), InputErrorKind::Version);

  std::string magic = good;
  magic[0] ^= 1;
  EXPECT_EQ(preflightError(magic).kind(), InputErrorKind::Malformed);

  // The grid's "class" metadata is a string: its value size beyond the file is Truncated.
  std::string meta = good;
  const std::size_t classType = after(meta, "class");
  ASSERT_EQ(meta.substr(classType + 4, 6), "string");
  store<std::uint32_t>(meta, classType + 4 + 6, 3'000'000'000u);
  EXPECT_EQ(preflightError(meta).kind(), InputErrorKind::Truncated);

  for (std::size_t cut : {std::size_t(3), std::size_t(60), good.size() / 2, good.size() - 1})
    EXPECT_EQ(preflightError(good.substr(0, cut)).kind(), InputErrorKind::Truncated) << cut;
}

// Fuzz findings (vdb_fuzz, 620 s on the H200 host): a grid whose "class" metadata is stored
// with another type ("3tring", "int64g"). OpenVDB read the grid, then threw a TypeError from
// setGridClass during the import's resampling, outside any reader.
TEST(VdbPreflight, ReservedMetadataOfAnotherTypeIsMalformed) {
  for (const char* name :
       {"fuzz-vdb-class-of-another-type-1.vdb", "fuzz-vdb-class-of-another-type-2.vdb"}) {
    const fs::path path = test::sourceDir() / "tests/world/data" / name;
    try {
      vdbToWorld(path, /*voxelSizeOverride=*/1.0, {});
      ADD_FAILURE() << name << " imported";
    } catch (const InputError& e) {
      std::printf("[ preflight ] %s\n", e.what());
      EXPECT_EQ(e.kind(), InputErrorKind::Malformed) << e.what();
      EXPECT_NE(std::string(e.what()).find("'class' has type"), std::string::npos) << e.what();
    }
  }
  std::string bytes = writeVdb("class.vdb", {sphere()}, openvdb::io::COMPRESS_BLOSC);
  const std::size_t type = after(bytes, "class");
  bytes[type + 4] = 'S';  // "String": not OpenVDB's "string"
  EXPECT_EQ(preflightError(bytes).kind(), InputErrorKind::Malformed);
}

}  // namespace
}  // namespace sdfstream
