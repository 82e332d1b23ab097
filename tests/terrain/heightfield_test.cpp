// Heightfield terrain: the analytic SDF against the brute-force distance to the heightfield's
// triangulation, heightmap decoding (8/16-bit) and its errors.
#include <cmath>
#include <filesystem>
#include <fstream>
#include <random>

#include <gtest/gtest.h>

#include "tests/gltf/gltf_test_util.h"
#include "tests/support/test_data.h"
#include "tests/terrain/png_writer.h"
#include "world/heightfield_source.h"

namespace sdfstream {
namespace {

namespace fs = std::filesystem;
using Kind = InputErrorKind;

// Closest-point distance from p to triangle abc (Ericson, Real-Time Collision Detection 5.1.5).
double pointTriangleDistance(glm::dvec3 p, glm::dvec3 a, glm::dvec3 b, glm::dvec3 c) {
  const glm::dvec3 ab = b - a, ac = c - a, ap = p - a;
  const double d1 = glm::dot(ab, ap), d2 = glm::dot(ac, ap);
  if (d1 <= 0 && d2 <= 0) return glm::length(p - a);
  const glm::dvec3 bp = p - b;
  const double d3 = glm::dot(ab, bp), d4 = glm::dot(ac, bp);
  if (d3 >= 0 && d4 <= d3) return glm::length(p - b);
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) return glm::length(p - (a + ab * (d1 / (d1 - d3))));
  const glm::dvec3 cp = p - c;
  const double d5 = glm::dot(ab, cp), d6 = glm::dot(ac, cp);
  if (d6 >= 0 && d5 <= d6) return glm::length(p - c);
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) return glm::length(p - (a + ac * (d2 / (d2 - d6))));
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && d4 - d3 >= 0 && d5 - d6 >= 0)
    return glm::length(p - (b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)))));
  const double denom = 1.0 / (va + vb + vc);
  return glm::length(p - (a + ab * (vb * denom) + ac * (vc * denom)));
}

// Signed distance to the triangulation of the pixel grid (diagonal (i,j)-(i+1,j+1)), searching
// the triangles within `reach` metres horizontally; the sign is that of y − triangulated height.
double bruteForce(const Heightfield& f, glm::dvec3 p, double reach) {
  const double m = f.metresPerPixel();
  const glm::dvec3 o = f.origin();
  auto vertex = [&](int i, int j) { return o + glm::dvec3(i * m, f.pixel(i, j), j * m); };
  const double u = (p.x - o.x) / m, v = (p.z - o.z) / m;
  const int r = int(std::ceil(reach / m)) + 1;
  double best = 1e30;
  for (int j = std::max(0, int(v) - r); j <= std::min(f.height() - 2, int(v) + r); ++j)
    for (int i = std::max(0, int(u) - r); i <= std::min(f.width() - 2, int(u) + r); ++i) {
      best = std::min(
          best, pointTriangleDistance(p, vertex(i, j), vertex(i + 1, j), vertex(i + 1, j + 1)));
      best = std::min(
          best, pointTriangleDistance(p, vertex(i, j), vertex(i + 1, j + 1), vertex(i, j + 1)));
    }
  const int i = std::min(int(u), f.width() - 2), j = std::min(int(v), f.height() - 2);
  const double fx = u - i, fz = v - j;
  const double h00 = f.pixel(i, j), h10 = f.pixel(i + 1, j), h01 = f.pixel(i, j + 1),
               h11 = f.pixel(i + 1, j + 1);
  const double h = o.y + (fx >= fz ? h00 + fx * (h10 - h00) + fz * (h11 - h10)
                                   : h00 + fz * (h01 - h00) + fx * (h11 - h01));
  return p.y >= h ? best : -best;
}

// A smooth 16-bit test terrain: 64×64 px at 1 m, heights 6 ± 3 m plus a gentle ramp.
struct SmoothTerrain {
  fs::path png;
  HeightfieldDesc desc;
};

SmoothTerrain smoothTerrain(const std::string& name, int bits) {
  const fs::path dir = test::scratchDir(name);
  const int n = 64;
  const double scale = 16.0, full = bits == 16 ? 65535.0 : 255.0;
  std::vector<std::uint16_t> v(std::size_t(n) * n);
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const double h =
          6.0 + 3.0 * std::sin(2 * M_PI * i / 40.0) * std::cos(2 * M_PI * j / 33.0) + 0.05 * i;
      v[std::size_t(j) * n + i] = std::uint16_t(std::lround(h / scale * full));
    }
  SmoothTerrain t;
  t.png = dir / "smooth.png";
  test::writeGrayPng(t.png, n, n, v, bits);
  t.desc.png = t.png;
  t.desc.metresPerPixel = 1.0;
  t.desc.heightScale = scale;
  t.desc.origin = glm::dvec3(-10.0, 2.0, 5.0);
  return t;
}

// Every sample of the bricks around the surface, through the SdfSource interface.
void checkAgainstBruteForce(const HeightfieldDesc& desc, double voxel, int lod) {
  const Heightfield field = Heightfield::load(desc);
  auto source = makeHeightfieldSource(desc);
  PartitionSpec spec;
  spec.voxelSize = voxel;
  spec.lodCount = lod + 1;
  spec.tileVoxels = 64 << lod;
  spec.origin = glm::dvec3(-10.25, 0.0, 0.0);  // not aligned to pixels on purpose
  source->prepareLod(spec, lod);
  const double vox = spec.lodVoxelSize(lod), brickMetres = 8 * vox;
  int compared = 0, signErrors = 0, bandErrors = 0;
  double worst = 0.0;
  for (double x = desc.origin.x + 4; x < desc.origin.x + 58; x += brickMetres * 1.7)
    for (double z = desc.origin.z + 4; z < desc.origin.z + 58; z += brickMetres * 1.3) {
      const glm::ivec3 b0 = glm::ivec3(
          glm::floor((glm::dvec3(x, field.heightAt(x, z), z) - spec.origin) / brickMetres));
      for (int dy = -1; dy <= 1; ++dy) {
        const glm::ivec3 brick = b0 + glm::ivec3(0, dy, 0);
        BrickSamples out;
        out.distance.fill(layout::kNarrowBand);
        out.materialDistance.fill(INFINITY);
        source->sampleBrick(lod, brick, out);
        for (int k = 0; k < 9; ++k)
          for (int j = 0; j < 9; ++j)
            for (int i = 0; i < 9; ++i) {
              const glm::dvec3 p = spec.origin + vox * glm::dvec3(brick * 8 + glm::ivec3(i, j, k));
              const double truth = bruteForce(field, p, 4 * vox) / vox;
              const double got = out.distance[std::size_t(brickSampleIndex(i, j, k))];
              ++compared;
              if (std::abs(truth) > 1.0 && (truth > 0) != (got > 0)) ++signErrors;
              if (std::abs(truth) < layout::kNarrowBand) {
                const double delta = std::abs(got - truth);
                worst = std::max(worst, delta);
                if (delta > 0.5) ++bandErrors;
              } else {
                // Outside the band the clamp must say so (within the same tolerance).
                if (std::abs(got) < layout::kNarrowBand - 0.5) ++bandErrors;
              }
            }
      }
    }
  EXPECT_GT(compared, 20000);
  EXPECT_EQ(signErrors, 0);
  EXPECT_EQ(bandErrors, 0) << "worst |delta| " << worst << " voxel";
  ::testing::Test::RecordProperty("worst_delta_voxels", std::to_string(worst));
  std::printf("voxel %.3g lod %d: %d samples, worst |delta| in band %.3f voxel\n", voxel, lod,
              compared, worst);
}

TEST(Heightfield, MatchesTriangulationDistance16Bit) {
  const SmoothTerrain t = smoothTerrain("hf16", 16);
  checkAgainstBruteForce(t.desc, 0.5, 0);
  checkAgainstBruteForce(t.desc, 0.25, 1);  // LOD 1 of a 0.25 m world: 0.5 m voxels
  checkAgainstBruteForce(t.desc, 1.0, 0);   // voxel = pixel
}

TEST(Heightfield, MatchesTriangulationDistance8Bit) {
  const SmoothTerrain t = smoothTerrain("hf8", 8);
  checkAgainstBruteForce(t.desc, 0.5, 0);
}

TEST(Heightfield, PlaneIsExact) {
  const fs::path dir = test::scratchDir("hf-plane");
  const int n = 32;
  std::vector<std::uint16_t> v(std::size_t(n) * n);
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) v[std::size_t(j) * n + i] = std::uint16_t(500 * (1 + i + 2 * j));
  test::writeGrayPng(dir / "plane.png", n, n, v, 16);
  HeightfieldDesc desc{dir / "plane.png", 2.0, 65.535, glm::dvec3(0.0), glm::vec3(0.5f)};
  const Heightfield f = Heightfield::load(desc);
  // 1000 units = 1 m and pixel (i, j) = (x/2, z/2), so h(x, z) = 0.5 + x/4 + z/2 metres.
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(8.0, 50.0), dy(-4.0, 4.0);
  const double norm = std::sqrt(1.0 + 0.0625 + 0.25);
  for (int s = 0; s < 500; ++s) {
    const double x = u(rng), z = u(rng) * 0.5;
    const double h = 0.5 + x / 4.0 + z / 2.0;
    ASSERT_NEAR(f.heightAt(x, z), h, 1e-4);
    const glm::dvec3 p(x, h + dy(rng), z);
    EXPECT_NEAR(f.signedDistance(p), (p.y - h) / norm, 1e-4) << x << " " << z;
  }
}

TEST(Heightfield, EightBitFullScaleAndPlacement) {
  const fs::path dir = test::scratchDir("hf-8bit");
  test::writeGrayPng(dir / "tiny.png", 3, 2, {0, 255, 128, 64, 32, 16}, 8);
  HeightfieldDesc desc{dir / "tiny.png", 5.0, 10.0, glm::dvec3(100.0, -3.0, 7.0), glm::vec3(0.5f)};
  const Heightfield f = Heightfield::load(desc);
  EXPECT_EQ(f.width(), 3);
  EXPECT_EQ(f.height(), 2);
  EXPECT_NEAR(f.heightAt(105.0, 7.0), 10.0 - 3.0, 1e-5);
  EXPECT_NEAR(f.heightAt(110.0, 7.0), 128.0 / 255.0 * 10.0 - 3.0, 1e-5);
  EXPECT_NEAR(f.heightAt(100.0, 12.0), 64.0 / 255.0 * 10.0 - 3.0, 1e-5);
  EXPECT_NEAR(f.heightAt(102.5, 7.0), 5.0 - 3.0, 1e-5);  // bilinear between 0 and 10
  EXPECT_NEAR(f.heightAt(-50.0, -50.0), -3.0, 1e-5);     // clamped to the edge pixel
  EXPECT_NEAR(f.boundsMax().x, 110.0, 1e-9);
  EXPECT_NEAR(f.boundsMax().z, 12.0, 1e-9);
  EXPECT_NEAR(f.boundsMax().y, 7.0, 1e-5);
  EXPECT_NEAR(f.boundsMin().y, -3.0, 1e-5);
}

TEST(Heightfield, SixteenBitKeepsPrecision) {
  const fs::path dir = test::scratchDir("hf-16bit");
  test::writeGrayPng(dir / "fine.png", 2, 2, {0, 1, 65534, 65535}, 16);
  HeightfieldDesc desc{dir / "fine.png", 1.0, 65535.0, glm::dvec3(0.0), glm::vec3(0.5f)};
  const Heightfield f = Heightfield::load(desc);
  EXPECT_NEAR(f.heightAt(1.0, 0.0), 1.0, 1e-6);  // one 16-bit step = 1 m here
  EXPECT_NEAR(f.heightAt(0.0, 1.0), 65534.0, 1e-2);
}

TEST(Heightfield, BrickFastPaths) {
  const SmoothTerrain t = smoothTerrain("hf-fast", 16);
  auto source = makeHeightfieldSource(t.desc);
  PartitionSpec spec;
  spec.voxelSize = 0.5;
  spec.tileVoxels = 64;
  source->prepareLod(spec, 0);
  BrickSamples out;
  out.distance.fill(layout::kNarrowBand);
  out.materialDistance.fill(INFINITY);
  out.albedo.fill(0);
  // Terrain heights are 2 + [3, 12] m; a brick at y = 40 m is far above.
  EXPECT_FALSE(source->sampleBrick(0, glm::ivec3(2, 10, 4), out));
  for (float d : out.distance) ASSERT_EQ(d, layout::kNarrowBand);
  for (std::uint32_t a : out.albedo) ASSERT_EQ(a, 0u);
  // y = -40 m is far below: wholly inside, no surface.
  EXPECT_FALSE(source->sampleBrick(0, glm::ivec3(2, -10, 4), out));
  for (float d : out.distance) ASSERT_EQ(d, -layout::kNarrowBand);
  // Distances-only callers (materialDistance 0) get no material.
  BrickSamples surface;
  surface.distance.fill(layout::kNarrowBand);
  surface.materialDistance.fill(0.0f);
  surface.albedo.fill(0);
  const double y = Heightfield::load(t.desc).heightAt(20.0, 20.0);
  EXPECT_TRUE(source->sampleBrick(0, glm::ivec3(5, int(std::floor(y / 4.0)), 5), surface));
  for (std::uint32_t a : surface.albedo) ASSERT_EQ(a, 0u);
  // With materials wanted, the surface brick is coloured.
  surface.materialDistance.fill(INFINITY);
  EXPECT_TRUE(source->sampleBrick(0, glm::ivec3(5, int(std::floor(y / 4.0)), 5), surface));
  int coloured = 0;
  for (std::uint32_t a : surface.albedo) coloured += a != 0;
  EXPECT_GT(coloured, 0);
}

TEST(Heightfield, BadImagesNameTheFile) {
  const fs::path dir = test::scratchDir("hf-bad");
  auto load = [&](const fs::path& png) {
    Heightfield::load(HeightfieldDesc{png, 1.0, 1.0, glm::dvec3(0.0), glm::vec3(0.5f)});
  };
  test::writeText(dir / "garbage.png", "this is not an image");
  std::string msg = test::expectInputError([&] { load(dir / "garbage.png"); }, Kind::Malformed);
  EXPECT_NE(msg.find("garbage.png"), std::string::npos) << msg;

  test::writeGrayPng(dir / "good.png", 16, 16, std::vector<std::uint16_t>(256, 9), 8);
  std::ifstream in(dir / "good.png", std::ios::binary);
  std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  test::writeText(dir / "truncated.png", bytes.substr(0, bytes.size() / 2));
  // Cut inside its IDAT chunk: the chunk walk sees the length run past the end.
  msg = test::expectInputError([&] { load(dir / "truncated.png"); }, Kind::Truncated);
  EXPECT_NE(msg.find("truncated.png"), std::string::npos) << msg;

  msg = test::expectInputError([&] { load(dir / "missing.png"); }, Kind::Io);
  EXPECT_NE(msg.find("missing.png"), std::string::npos) << msg;
  test::expectInputError([&] { load(dir); }, Kind::Io);

  test::writeGrayPng(dir / "one.png", 1, 1, {7}, 8);
  msg = test::expectInputError([&] { load(dir / "one.png"); }, Kind::Empty);
  EXPECT_NE(msg.find("one.png"), std::string::npos) << msg;

  test::expectInputError(
      [&] {
        Heightfield::load(
            HeightfieldDesc{dir / "good.png", 0.0, 1.0, glm::dvec3(0.0), glm::vec3(0.5f)});
      },
      Kind::Malformed);
}

// Over-limit allocation, found reviewing what fuzz/heightmap_fuzz.cpp reaches: stb's BMP decoder
// (like its TGA and PSD ones) accepts a file that ends right after a header declaring many pixels and returns
// zeros, so 1 KB declaring 16384² pixels cost ~4 GiB. Heightmaps are PNG only now; this one
// declares 2048² so that without the check it would load (flat) instead of failing.
TEST(Heightfield, TruncatedBmpIsNotAHeightmap) {
  std::string bmp(54 + 1024, '\0');
  auto put = [&](std::size_t at, std::uint32_t v, int n) {
    for (int i = 0; i < n; ++i) bmp[at + std::size_t(i)] = char(v >> (8 * i));
  };
  bmp[0] = 'B', bmp[1] = 'M';
  put(2, std::uint32_t(bmp.size()), 4), put(10, 54 + 1024, 4);  // file size, pixel offset
  put(14, 40, 4), put(18, 2048, 4), put(22, 2048, 4);            // info header: 2048 × 2048
  put(26, 1, 2), put(28, 8, 2), put(46, 256, 4);                 // 1 plane, 8 bits, palette
  const fs::path dir = test::scratchDir("hf-bmp");
  test::writeText(dir / "flat.png", bmp);
  const std::string msg = test::expectInputError(
      [&] { Heightfield::load(HeightfieldDesc{dir / "flat.png", 1.0, 1.0, glm::dvec3(0.0), {}}); },
      Kind::Malformed);
  EXPECT_NE(msg.find("flat.png: not a PNG file"), std::string::npos) << msg;
}

// Fuzz finding (heightmap_fuzz, within seconds): for an unknown critical PNG chunk stb's failure
// reason holds the chunk's four type bytes from the file, here a newline, which made the error
// two lines.
TEST(Heightfield, UnknownChunkTypeKeepsTheErrorOneLine) {
  std::string png("\x89PNG\r\n\x1a\n", 8);
  auto chunk = [&](const std::string& type, const std::string& data) {
    for (int shift : {24, 16, 8, 0}) png += char(data.size() >> shift);
    png += type + data + std::string(4, '\0');  // stb does not check the CRC
  };
  chunk("IHDR", std::string("\0\0\0\4\0\0\0\4\x08\0\0\0\0", 13));  // 4x4, 8-bit grey
  chunk("\nAAA", "");  // upper-case first letter bit clear: critical, so stb refuses it
  const fs::path dir = test::scratchDir("hf-chunk");
  test::writeText(dir / "chunk.png", png);
  const std::string msg = test::expectInputError(
      [&] { Heightfield::load(HeightfieldDesc{dir / "chunk.png", 1.0, 1.0, glm::dvec3(0.0), {}}); },
      Kind::Malformed);
  EXPECT_EQ(msg.find('\n'), std::string::npos) << msg;
  EXPECT_NE(msg.find("\\x0aAAA PNG chunk not known"), std::string::npos) << msg;
}

// A chunk whose length claims more bytes than the file holds: stb would grow its IDAT buffer to
// the claimed length (2 GiB from a 60-byte file) before reading; refused from the chunk walk.
TEST(Heightfield, ChunkLongerThanTheFileIsTruncated) {
  std::string png("\x89PNG\r\n\x1a\n", 8);
  auto chunk = [&](const std::string& type, const std::string& data, std::uint32_t length) {
    for (int shift : {24, 16, 8, 0}) png += char(length >> shift);
    png += type + data + std::string(4, '\0');
  };
  chunk("IHDR", std::string("\0\0\0\4\0\0\0\4\x08\0\0\0\0", 13), 13);  // 4x4, 8-bit grey
  chunk("IDAT", "x", 0x7fffffffu);
  const fs::path dir = test::scratchDir("hf-long-chunk");
  test::writeText(dir / "long.png", png);
  const std::string msg = test::expectInputError(
      [&] { Heightfield::load(HeightfieldDesc{dir / "long.png", 1.0, 1.0, glm::dvec3(0.0), {}}); },
      Kind::Truncated);
  EXPECT_NE(msg.find("2147483647 bytes"), std::string::npos) << msg;
  // What heightmap_fuzz found on the H200 host (92 bytes): an IDAT whose length swallows IEND,
  // then a chunk claiming 1.6 GB; stb reallocated 2 GiB before reading it.
  const fs::path found = test::sourceDir() / "tests/terrain/data/fuzz-idat-claims-1.6GB.png";
  const std::string fuzzed = test::expectInputError(
      [&] { Heightfield::load(HeightfieldDesc{found, 1.0, 1.0, glm::dvec3(0.0), {}}); },
      Kind::Truncated);
  EXPECT_NE(fuzzed.find("1610612757 bytes"), std::string::npos) << fuzzed;
  // The next run's finding (76 bytes): the file ends 10 bytes into a chunk claiming 1.3 GB, a
  // whole header but no CRC; stb reallocated 2 GiB for it.
  const fs::path headerOnly =
      test::sourceDir() / "tests/terrain/data/fuzz-last-chunk-header-claims-1.3GB.png";
  const std::string cut = test::expectInputError(
      [&] { Heightfield::load(HeightfieldDesc{headerOnly, 1.0, 1.0, glm::dvec3(0.0), {}}); },
      Kind::Truncated);
  EXPECT_NE(cut.find("1308622848 bytes"), std::string::npos) << cut;
}

}  // namespace
}  // namespace sdfstream
