// Mesh → SDF bricks against brute force on meshes built here (fixed seeds), the open-sheet rule,
// the memory limit and the colour encoders.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <ctime>
#include <random>
#include <vector>

#include <gtest/gtest.h>
#include <glm/gtc/matrix_transform.hpp>

#include "core/error.h"
#include "shaders/shared/color_codec.h"
#include "tests/support/test_data.h"
#include "tests/world/mesh_fixtures.h"
#include "world/brick_sampler.h"
#include "world/color_pack.h"
#include "world/gltf_import.h"
#include "world/mesh_to_sdf.h"

namespace sdfstream {
namespace {

struct ErrorStats {
  std::vector<double> bandErrors;  // |Δ| in voxels where |d_true| < 2.5
  int signChecked = 0, farPoints = 0;
};

// Samples the world at `count` uniform points in the mesh bbox grown by 4 voxels and checks
// against brute force (see the brief in mesh_to_sdf.h): |Δ| ≤ 0.5 voxel in the band, correct
// sign outside a 1-voxel shell, and points in no brick at least 2 voxels from the surface.
ErrorStats checkAgainstBruteForce(const TriangleScene& scene, const World& world, int count,
                                  unsigned seed) {
  BrickSampler sampler(world);
  const double vs = world.voxelSize;
  const glm::dvec3 lo = glm::dvec3(scene.boundsMin()) - 4.0 * vs;
  const glm::dvec3 hi = glm::dvec3(scene.boundsMax()) + 4.0 * vs;
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  ErrorStats stats;
  for (int i = 0; i < count; ++i) {
    glm::dvec3 p = lo + (hi - lo) * glm::dvec3(u(rng), u(rng), u(rng));
    const bool inside = std::abs(test::windingNumber(scene, p)) > 0.5;
    const double dTrue = (inside ? -1.0 : 1.0) * test::bruteForceDistance(scene, p) / vs;
    std::optional<float> d = sampler.distanceVoxels(p);
    if (!d) {
      ++stats.farPoints;
      EXPECT_GE(std::abs(dTrue), 2.0) << "surface dropped near " << p.x << "," << p.y << "," << p.z;
      continue;
    }
    if (std::abs(dTrue) < 2.5) {
      stats.bandErrors.push_back(std::abs(*d - dTrue));
      EXPECT_LE(std::abs(*d - dTrue), 0.5)
          << "at " << p.x << "," << p.y << "," << p.z << " true " << dTrue << " sampled " << *d;
    }
    if (std::abs(dTrue) > 1.0) {
      ++stats.signChecked;
      EXPECT_EQ(*d < 0, dTrue < 0) << "sign at " << p.x << "," << p.y << "," << p.z << " true "
                                   << dTrue << " sampled " << *d;
    }
  }
  return stats;
}

void report(const char* name, ErrorStats s) {
  ASSERT_FALSE(s.bandErrors.empty());
  std::sort(s.bandErrors.begin(), s.bandErrors.end());
  std::printf(
      "[ sdf error ] %s: %zu band points, |delta| max %.4f median %.4f voxel; %d sign "
      "checks, %d points in no brick\n",
      name, s.bandErrors.size(), s.bandErrors.back(), s.bandErrors[s.bandErrors.size() / 2],
      s.signChecked, s.farPoints);
}

TEST(MeshToSdf, IcosphereMatchesBruteForce) {
  TriangleScene sphere = test::icosphere({0.13f, -0.07f, 0.31f}, 1.0f, 3);
  ASSERT_TRUE(isClosedMesh(sphere));
  World world = meshToWorld(sphere, 0.05, {});
  ASSERT_FALSE(world.bricks.empty());
  for (std::size_t i = 1; i < world.bricks.size(); ++i)
    ASSERT_TRUE(brickCoordLess(world.bricks[i - 1].coord, world.bricks[i].coord));
  report("icosphere r=20 voxels", checkAgainstBruteForce(sphere, world, 10000, 1234));
}

TEST(MeshToSdf, RotatedBoxMatchesBruteForce) {
  glm::mat3 rot = glm::mat3(glm::rotate(glm::mat4(1.0f), 0.6f, glm::normalize(glm::vec3(1, 2, 3))));
  TriangleScene box = test::rotatedBox({0.2f, 0.1f, -0.3f}, {1.0f, 0.6f, 0.35f}, rot);
  ASSERT_TRUE(isClosedMesh(box));  // unshared vertices weld by position
  World world = meshToWorld(box, 0.04, {});
  report("rotated box", checkAgainstBruteForce(box, world, 10000, 99));
}

TEST(MeshToSdf, MaterialsComeFromTheClosestTriangle) {
  TriangleScene sphere = test::withDefaultMaterial(test::icosphere({0, 0, 0}, 1.0f, 2),
                                                   {0.5f, 0.25f, 1.0f, 1.0f}, {2.0f, 0.0f, 0.5f});
  World world = meshToWorld(sphere, 0.1, {});
  const std::uint32_t albedo = packAlbedo({0.5f, 0.25f, 1.0f, 1.0f});
  int surfaceCells = 0;
  for (const Brick& b : world.bricks)
    for (int c = 0; c < int(layout::kBrickMaterialCount); ++c) {
      if (b.albedo[c] == 0) continue;  // no triangle within the band
      ++surfaceCells;
      ASSERT_EQ(b.albedo[c], albedo);
      glm::vec3 e = layout::unpackRgb9e5(b.emission[c]);
      ASSERT_NEAR(e.r, 2.0f, 1e-6f);
      ASSERT_NEAR(e.g, 0.0f, 1e-6f);
      ASSERT_NEAR(e.b, 0.5f, 1e-6f);
    }
  EXPECT_GT(surfaceCells, 1000);
}

TEST(MeshToSdf, OpenSheetBecomesThinShell) {
  const double vs = 0.1;
  const float z0 = 0.03f;  // 0.3 voxel above a sample plane
  TriangleScene quad = test::quadSheet(1.0f, z0);
  EXPECT_FALSE(isClosedMesh(quad));
  World world = meshToWorld(quad, vs, {});
  BrickSampler sampler(world);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-0.8, 0.8);
  double worst = 0;
  for (int line = 0; line < 500; ++line) {
    const double x = u(rng), y = u(rng);
    std::optional<float> prev;
    double prevZ = 0;
    int crossings = 0;
    float minD = 1e9f;
    for (double z = z0 - 2.0 * vs; z <= z0 + 2.0 * vs; z += 0.01 * vs) {
      std::optional<float> d = sampler.distanceVoxels({x, y, z});
      ASSERT_TRUE(d) << "no brick next to the sheet";
      minD = std::min(minD, *d);
      if (prev && ((*prev < 0) != (*d < 0))) {
        const double zc = prevZ + (z - prevZ) * (*prev / (*prev - *d));
        worst = std::max(worst, std::abs(zc - z0) / vs);
        ++crossings;
      }
      prev = d;
      prevZ = z;
    }
    EXPECT_LT(minD, 0.0f) << "shell has no inside at " << x << "," << y;
    EXPECT_EQ(crossings, 2) << "at " << x << "," << y;
  }
  std::printf("[ sdf error ] open sheet: zero crossings at most %.4f voxel from the sheet\n",
              worst);
  EXPECT_LE(worst, 0.5 + 0.01);
}

TEST(MeshToSdf, ClosedMeshDetection) {
  TriangleScene sphere = test::icosphere({0, 0, 0}, 1.0f, 1);
  EXPECT_TRUE(isClosedMesh(sphere));
  sphere.triangles.pop_back();
  EXPECT_FALSE(isClosedMesh(sphere));
}

// A sealed room of closed boxes (slabs and walls overlapping, no shared edge): closed by edges,
// but its air is enclosed, and OpenVDB's sign flood fill alone would call it inside (solid).
TEST(MeshToSdf, SealedRoomOfClosedBoxesKeepsItsAirOutside) {
  const glm::mat3 axes(1.0f);
  TriangleScene room;
  for (const auto& [centre, half] :
       {std::pair{glm::vec3(0, -0.1f, 0), glm::vec3(1.2f, 0.1f, 1.2f)},
        std::pair{glm::vec3(0, 1.1f, 0), glm::vec3(1.2f, 0.1f, 1.2f)},
        std::pair{glm::vec3(0, 0.5f, -1.1f), glm::vec3(1.2f, 0.55f, 0.1f)},
        std::pair{glm::vec3(0, 0.5f, 1.1f), glm::vec3(1.2f, 0.55f, 0.1f)},
        std::pair{glm::vec3(-1.1f, 0.5f, 0), glm::vec3(0.1f, 0.55f, 1.05f)},
        std::pair{glm::vec3(1.1f, 0.5f, 0), glm::vec3(0.1f, 0.55f, 1.05f)}}) {
    const TriangleScene box = test::rotatedBox(centre, half, axes);
    const auto base = std::uint32_t(room.positions.size());
    room.positions.insert(room.positions.end(), box.positions.begin(), box.positions.end());
    for (const glm::uvec3& t : box.triangles) room.triangles.push_back(t + base);
  }
  room = test::withDefaultMaterial(std::move(room));
  ASSERT_TRUE(isClosedMesh(room));
  const World world = meshToWorld(room, 0.05, {});
  BrickSampler sampler(world);
  // Air 2 and 3 voxels above the floor, below the ceiling and beside a wall: outside.
  for (const glm::dvec3 p : {glm::dvec3(0, 0.1, 0), glm::dvec3(0.3, 0.15, -0.2),
                             glm::dvec3(0, 0.9, 0.1), glm::dvec3(0.9, 0.5, 0.0)}) {
    const std::optional<float> d = sampler.distanceVoxels(p);
    ASSERT_TRUE(d.has_value()) << "no brick at " << p.y;
    EXPECT_GT(*d, 1.0f) << "air at " << p.x << "," << p.y << "," << p.z << " reads " << *d;
  }
  // A closed box keeps its signed SDF, also wound inside out (the flood fill is right there).
  TriangleScene box = test::rotatedBox({0, 0, 0}, {0.5f, 0.4f, 0.3f}, axes);
  for (glm::uvec3& t : box.triangles) std::swap(t.y, t.z);
  const World inverted = meshToWorld(box, 0.05, {});
  EXPECT_LT(*BrickSampler(inverted).distanceVoxels(glm::dvec3(0.0, 0.3, 0.0)), -1.5f);
}

TEST(MeshToSdf, TooLargeFailsFastWithoutAllocating) {
  TriangleScene box = test::rotatedBox({0, 0, 0}, {50, 50, 50}, glm::mat3(1.0f));
  const auto start = std::chrono::steady_clock::now();
  try {
    meshToWorld(box, 1e-4, {});
    FAIL() << "expected TooLarge";
  } catch (const InputError& e) {
    EXPECT_EQ(e.kind(), InputErrorKind::TooLarge) << e.what();
    EXPECT_NE(std::string(e.what()).find("0.0001"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("GiB"), std::string::npos) << e.what();
  }
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), 0.5);
}

TEST(MeshToSdf, EmptySceneIsEmpty) {
  TriangleScene empty;
  empty.source = "empty";
  try {
    meshToWorld(empty, 0, {});
    FAIL();
  } catch (const InputError& e) {
    EXPECT_EQ(e.kind(), InputErrorKind::Empty);
  }
}

TEST(MeshToSdf, DefaultVoxelSizeIsLargestExtentOver112) {
  TriangleScene box = test::rotatedBox({0, 0, 0}, {2.0f, 1.0f, 0.5f}, glm::mat3(1.0f));
  EXPECT_DOUBLE_EQ(defaultVoxelSize(box), 4.0 / 112.0);
  EXPECT_DOUBLE_EQ(meshToWorld(box, 0, {}).voxelSize, 4.0 / 112.0);
}

TEST(ColorPack, Rgb9e5RoundTrip) {
  std::mt19937 rng(42);
  std::uniform_real_distribution<float> logu(-12.0f, 15.0f);
  for (int i = 0; i < 100000; ++i) {
    glm::vec3 c(std::exp2(logu(rng)), std::exp2(logu(rng)), std::exp2(logu(rng)));
    glm::vec3 back = layout::unpackRgb9e5(packRgb9e5(c));
    const float maxc = std::max({c.r, c.g, c.b});
    // Shared exponent: every channel is within half a step of the largest channel's scale.
    const float step = std::exp2(std::floor(std::log2(maxc)) - 8.0f);
    for (int k = 0; k < 3; ++k) ASSERT_LE(std::abs(back[k] - c[k]), step) << c[k];
  }
  EXPECT_EQ(packRgb9e5({0, 0, 0}), 0u);
  EXPECT_EQ(layout::unpackRgb9e5(packRgb9e5({1, 0.5f, 0.25f})), glm::vec3(1, 0.5f, 0.25f));
  EXPECT_EQ(layout::unpackRgb9e5(packRgb9e5({-1, NAN, 3})), glm::vec3(0, 0, 3));
  EXPECT_NEAR(layout::unpackRgb9e5(packRgb9e5({1e9f, 0, 0})).r, 65408.0f, 1e-3f);
}

TEST(ColorPack, AlbedoSrgb) {
  EXPECT_EQ(packAlbedo({0, 0, 0, 0}), 0u);
  EXPECT_EQ(packAlbedo({1, 1, 1, 1}), 0xffffffffu);
  EXPECT_EQ(packAlbedo({0.2158605f, 0, 0, 1}) & 255u, 128u);  // sRGB 128/255 = linear 0.21586
  glm::vec4 back = layout::unpackAlbedo(packAlbedo({0.2f, 0.4f, 0.6f, 0.5f}));
  EXPECT_NEAR(back.a, 0.5f, 1.0f / 255);
}

// Throughput on a real mesh (skips while loadGltf cannot read it).
TEST(MeshToSdf, ImportTimePerMillionTriangles) {
  const auto path = test::assimpModels() / "glTF2/2CylinderEngine-glTF-Binary/2CylinderEngine.glb";
  if (!std::filesystem::exists(path)) GTEST_SKIP() << path << " absent";
  TriangleScene scene = loadGltf(path);
  const auto start = std::chrono::steady_clock::now();
  const std::clock_t cpuStart = std::clock();
  World world = meshToWorld(scene, 0, {});
  const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const double cpu = double(std::clock() - cpuStart) / CLOCKS_PER_SEC;
  const double mtris = double(scene.triangles.size()) * 1e-6;
  std::printf(
      "[ import    ] 2CylinderEngine: %zu triangles, voxel %.4g, %zu bricks, wall %.2f s "
      "(%.1f s per million triangles), CPU %.2f s (%.1f s per million), closed: %d\n",
      scene.triangles.size(), world.voxelSize, world.bricks.size(), s, s / mtris, cpu, cpu / mtris,
      int(isClosedMesh(scene)));
  EXPECT_FALSE(world.bricks.empty());
}

}  // namespace
}  // namespace sdfstream
