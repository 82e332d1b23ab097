// Object SDF distances against analytic and brute-force references: boxes (axis-aligned and
// rotated), a tessellated sphere, a concave torus, a 121k-triangle open model and an open sheet.
#include <cmath>
#include <filesystem>
#include <numbers>
#include <random>

#include <gtest/gtest.h>

#include "objects/object_sdf.h"
#include "objects/primitive_meshes.h"
#include "tests/support/object_sdf_settings.h"
#include "tests/support/test_data.h"
#include "tests/world/mesh_fixtures.h"
#include "world/gltf_import.h"
#include "world/mesh_to_sdf.h"

namespace sdfstream {
namespace {

// How close to brute force every sample must be, in grid voxels.
constexpr double kSampleTolerance = 0.05;

double sdBox(glm::dvec3 p, glm::dvec3 half) {
  const glm::dvec3 q = glm::abs(p) - half;
  return glm::length(glm::max(q, 0.0)) + std::min(std::max({q.x, q.y, q.z}), 0.0);
}

// Signed distance to a closed mesh by brute force: winding number for the sign.
double bruteForceSigned(const TriangleScene& mesh, glm::dvec3 p) {
  const double d = test::bruteForceDistance(mesh, p);
  return test::windingNumber(mesh, p) > 0.5 ? -d : d;
}

TEST(ObjectSdf, BoxEqualsAnalyticDistanceAtEverySample) {
  const glm::vec3 half(0.7f, 0.4f, 0.25f);
  const TriangleScene mesh = makeBoxMesh(half, glm::vec4(0.5f));
  const ObjectSdf sdf = buildObjectSdf(mesh, {});
  ASSERT_TRUE(sdf.closed);
  ASSERT_EQ(sdf.distance.size(), sdf.sampleCount());
  double worst = 0;
  int inside = 0, far = 0;
  for (std::uint32_t z = 0; z < sdf.dims.z; ++z)
    for (std::uint32_t y = 0; y < sdf.dims.y; ++y)
      for (std::uint32_t x = 0; x < sdf.dims.x; ++x) {
        const double want =
            sdBox(glm::dvec3(sdf.samplePosition(x, y, z)), glm::dvec3(half)) / double(sdf.voxel);
        const double got = sdf.distance[sdf.index(x, y, z)];
        worst = std::max(worst, std::abs(got - want));
        inside += want < -kSampleTolerance;
        far += std::abs(want) > 8.0;  // well outside any narrow band
        if (std::abs(want) > kSampleTolerance) {
          ASSERT_EQ(got < 0, want < 0) << x << " " << y << " " << z;
        }
      }
  EXPECT_LE(worst, kSampleTolerance);
  EXPECT_GT(inside, 1000);
  EXPECT_GT(far, 1000);
}

TEST(ObjectSdf, BoxTrilinearWithinInterpolationBoundAtRandomPoints) {
  const glm::vec3 half(0.3f, 0.5f, 0.2f);
  const ObjectSdf sdf =
      buildObjectSdf(makeBoxMesh(half, glm::vec4(0.5f)), test::objectSdfResolution(32));
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  // Trilinear interpolation of a 1-Lipschitz field errs by at most the weighted distance to the
  // cell corners, <= sqrt(3)/2 voxel; on average far less.
  const double bound = kSampleTolerance + std::sqrt(3.0) / 2.0;
  double sum = 0;
  const int n = 20000;
  for (int i = 0; i < n; ++i) {
    const glm::vec3 p =
        sdf.gridMin + glm::vec3(u(rng), u(rng), u(rng)) * (sdf.gridMax() - sdf.gridMin);
    const double want = sdBox(glm::dvec3(p), glm::dvec3(half)) / sdf.voxel;
    const double got = sdf.sampleTrilinear(p);
    ASSERT_LE(std::abs(got - want), bound) << p.x << " " << p.y << " " << p.z;
    if (std::abs(want) > bound) {
      ASSERT_EQ(got < 0, want < 0);
    }
    sum += std::abs(got - want);
  }
  EXPECT_LT(sum / n, 0.05);
  // Clamped to the box: a far point reads the nearest face's samples.
  EXPECT_FLOAT_EQ(sdf.sampleTrilinear(glm::vec3(100, 0, 0)),
                  sdf.sampleTrilinear(glm::vec3(sdf.gridMax().x, 0, 0)));
}

TEST(ObjectSdf, SphereMatchesBruteForceAndAnalyticWithinTessellation) {
  const float r = 0.6f;
  const std::uint32_t segments = 24;
  const TriangleScene mesh = makeSphereMesh(r, glm::vec4(0.5f), segments);
  const ObjectSdf sdf = buildObjectSdf(mesh, test::objectSdfResolution(48));
  ASSERT_TRUE(sdf.closed);
  // The faces lie inside the sphere by at most r − (closest approach of the mesh to the centre),
  // measured here from the triangles, so signed(mesh) − signed(sphere) ∈ [0, gap].
  const double gap = r - test::bruteForceDistance(mesh, glm::dvec3(0.0));
  ASSERT_GT(gap, 0.0);
  ASSERT_LT(gap, r * (1 - std::cos(std::numbers::pi / segments) *
                              std::cos(std::numbers::pi / (2 * sphereRings(segments)))) +
                     1e-6);
  const double gapVoxels = gap / sdf.voxel;
  for (std::size_t i = 0; i < sdf.sampleCount(); ++i) {
    const std::uint32_t x = std::uint32_t(i % sdf.dims.x),
                        y = std::uint32_t(i / sdf.dims.x % sdf.dims.y),
                        z = std::uint32_t(i / (std::size_t(sdf.dims.x) * sdf.dims.y));
    const double sphere = (glm::length(glm::dvec3(sdf.samplePosition(x, y, z))) - r) / sdf.voxel;
    const double diff = sdf.distance[i] - sphere;
    ASSERT_GE(diff, -kSampleTolerance) << i;
    ASSERT_LE(diff, gapVoxels + kSampleTolerance) << i;
  }
  std::mt19937 rng(11);
  std::uniform_int_distribution<std::uint32_t> ux(0, sdf.dims.x - 1), uy(0, sdf.dims.y - 1),
      uz(0, sdf.dims.z - 1);
  for (int k = 0; k < 1500; ++k) {
    const std::uint32_t x = ux(rng), y = uy(rng), z = uz(rng);
    const double want = bruteForceSigned(mesh, glm::dvec3(sdf.samplePosition(x, y, z))) / sdf.voxel;
    ASSERT_NEAR(sdf.distance[sdf.index(x, y, z)], want, kSampleTolerance)
        << x << " " << y << " " << z;
  }
}

TEST(ObjectSdf, RotatedBoxMatchesBruteForce) {
  // Faces not aligned with the grid: exactness must not depend on the box axes.
  const glm::mat3 rotation =
      glm::mat3_cast(glm::angleAxis(0.6f, glm::normalize(glm::vec3(1, 2, 3))));
  const TriangleScene mesh =
      test::rotatedBox(glm::vec3(1, 2, 3), glm::vec3(0.5f, 0.3f, 0.2f), rotation);
  const ObjectSdf sdf = buildObjectSdf(mesh, test::objectSdfResolution(32));
  std::mt19937 rng(3);
  std::uniform_int_distribution<std::uint32_t> ux(0, sdf.dims.x - 1), uy(0, sdf.dims.y - 1),
      uz(0, sdf.dims.z - 1);
  for (int k = 0; k < 2000; ++k) {
    const std::uint32_t x = ux(rng), y = uy(rng), z = uz(rng);
    const double want = bruteForceSigned(mesh, glm::dvec3(sdf.samplePosition(x, y, z))) / sdf.voxel;
    ASSERT_NEAR(sdf.distance[sdf.index(x, y, z)], want, kSampleTolerance)
        << x << " " << y << " " << z;
  }
}

// A closed torus lying in the xz plane: concave, with a medial circle inside and a hole whose
// closest triangles lie on the far side -- where grown closest-triangle fields go wrong first.
TriangleScene torus(float major, float minor, std::uint32_t around, std::uint32_t tube) {
  TriangleScene scene;
  for (std::uint32_t i = 0; i < around; ++i)
    for (std::uint32_t j = 0; j < tube; ++j) {
      const double u = 2 * std::numbers::pi * i / around, v = 2 * std::numbers::pi * j / tube;
      const double r = major + minor * std::cos(v);
      scene.positions.push_back(
          glm::vec3(glm::dvec3(r * std::cos(u), minor * std::sin(v), r * std::sin(u))));
    }
  auto at = [&](std::uint32_t i, std::uint32_t j) { return (i % around) * tube + j % tube; };
  for (std::uint32_t i = 0; i < around; ++i)
    for (std::uint32_t j = 0; j < tube; ++j) {
      scene.triangles.push_back({at(i, j), at(i, j + 1), at(i + 1, j + 1)});
      scene.triangles.push_back({at(i, j), at(i + 1, j + 1), at(i + 1, j)});
    }
  scene.source = "torus";
  return test::withDefaultMaterial(std::move(scene));
}

TEST(ObjectSdf, ConcaveTorusMatchesBruteForce) {
  const TriangleScene mesh = torus(0.6f, 0.2f, 32, 12);
  ASSERT_TRUE(isClosedMesh(mesh));
  const ObjectSdf sdf = buildObjectSdf(mesh, test::objectSdfResolution(40));
  ASSERT_TRUE(sdf.closed);
  std::mt19937 rng(17);
  std::uniform_int_distribution<std::uint32_t> ux(0, sdf.dims.x - 1), uy(0, sdf.dims.y - 1),
      uz(0, sdf.dims.z - 1);
  int inside = 0;
  for (int k = 0; k < 1500; ++k) {
    const std::uint32_t x = ux(rng), y = uy(rng), z = uz(rng);
    const double want = bruteForceSigned(mesh, glm::dvec3(sdf.samplePosition(x, y, z))) / sdf.voxel;
    inside += want < 0;
    ASSERT_NEAR(sdf.distance[sdf.index(x, y, z)], want, kSampleTolerance)
        << x << " " << y << " " << z;
  }
  EXPECT_GT(inside, 20);
  // The centre of the hole is outside, major − minor from the tube (the peak of a cone there,
  // which trilinear filtering flattens by up to about a voxel).
  EXPECT_NEAR(sdf.sampleTrilinear(glm::vec3(0.0f)) * sdf.voxel, 0.4, sdf.voxel);
}

TEST(ObjectSdf, ManyTriangleOpenMeshMatchesBruteForce) {
  // A real model: 121k triangles in many open parts (assimp-testmodels, installed by setup).
  const std::filesystem::path file =
      test::assimpModels() / "glTF2/2CylinderEngine-glTF-Binary/2CylinderEngine.glb";
  if (!std::filesystem::exists(file)) GTEST_SKIP() << file << " absent";
  const TriangleScene mesh = loadGltf(file);
  const ObjectSdf sdf = buildObjectSdf(mesh, test::objectSdfResolution(48));
  EXPECT_FALSE(sdf.closed);
  std::mt19937 rng(23);
  std::uniform_int_distribution<std::uint32_t> ux(0, sdf.dims.x - 1), uy(0, sdf.dims.y - 1),
      uz(0, sdf.dims.z - 1);
  for (int k = 0; k < 150; ++k) {
    const std::uint32_t x = ux(rng), y = uy(rng), z = uz(rng);
    const double want =
        test::bruteForceDistance(mesh, glm::dvec3(sdf.samplePosition(x, y, z))) / sdf.voxel - 0.5;
    ASSERT_NEAR(sdf.distance[sdf.index(x, y, z)], want, kSampleTolerance)
        << x << " " << y << " " << z;
  }
}

TEST(ObjectSdf, OpenSheetIsUnsignedMinusHalfAVoxel) {
  const TriangleScene mesh = test::quadSheet(0.5f, 0.25f);
  const ObjectSdf sdf = buildObjectSdf(mesh, test::objectSdfResolution(24));
  EXPECT_FALSE(sdf.closed);
  EXPECT_EQ(sdf.dims.z, 1u + 2 * ObjectSdfSettings{}.padVoxels);  // flat axis: 1 sample + pads
  for (std::size_t i = 0; i < sdf.sampleCount(); ++i) {
    const std::uint32_t x = std::uint32_t(i % sdf.dims.x),
                        y = std::uint32_t(i / sdf.dims.x % sdf.dims.y),
                        z = std::uint32_t(i / (std::size_t(sdf.dims.x) * sdf.dims.y));
    const double want =
        test::bruteForceDistance(mesh, glm::dvec3(sdf.samplePosition(x, y, z))) / sdf.voxel - 0.5;
    ASSERT_NEAR(sdf.distance[i], want, kSampleTolerance) << i;
  }
}

}  // namespace
}  // namespace sdfstream
