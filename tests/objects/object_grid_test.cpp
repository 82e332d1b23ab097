// The object SDF grid (resolution rule), materials from the closest triangle, determinism and
// content hashes, errors, and the built-in primitive meshes.
#include <cmath>
#include <numbers>

#include <gtest/gtest.h>

#include "core/error.h"
#include "objects/object_sdf.h"
#include "objects/primitive_meshes.h"
#include "tests/support/object_sdf_settings.h"
#include "world/color_pack.h"
#include "world/mesh_to_sdf.h"

namespace sdfstream {
namespace {

// Resolution rule (object_sdf.h): voxel = longest / clamp(ceil(longest / target), min, max), each
// axis ceil(extent / voxel) + 1 + 2·pad samples, centred.
TEST(ObjectSdf, ResolutionRule) {
  struct Case {
    glm::vec3 half;
    double target;
    std::uint32_t intervals;  // expected along the longest axis
  };
  const Case cases[] = {
      {glm::vec3(0.05f), 0.0, 64},                // target 0: always max, tiny object
      {glm::vec3(50.0f), 0.0, 64},                // target 0: always max, huge object
      {glm::vec3(0.25f, 0.1f, 0.1f), 0.1, 16},    // 5 wanted, clamped up to min
      {glm::vec3(50.0f, 1.0f, 1.0f), 0.1, 64},    // 1000 wanted, clamped down to max
      {glm::vec3(2.0f, 0.5f, 0.165f), 0.11, 37},  // in range: ceil(4 / 0.11)
      {glm::vec3(0.3f, 2.05f, 0.3f), 0.13, 32},   // ceil(4.1 / 0.13), longest axis y
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(testing::Message() << "half " << c.half.x << "," << c.half.y << "," << c.half.z
                                    << " target " << c.target);
    ObjectSdfSettings settings;
    settings.targetVoxel = c.target;
    const TriangleScene mesh = makeBoxMesh(c.half, glm::vec4(1.0f));
    const ObjectSdf grid = objectGridFor(mesh, settings);
    const glm::dvec3 extent = 2.0 * glm::dvec3(c.half);
    const double longest = std::max({extent.x, extent.y, extent.z});
    EXPECT_NEAR(grid.voxel, longest / c.intervals, 1e-6 * longest);
    for (int a = 0; a < 3; ++a) {
      const std::uint32_t want =
          std::uint32_t(std::ceil(extent[a] / grid.voxel - 1e-4)) + 1 + 2 * settings.padVoxels;
      EXPECT_EQ(grid.dims[a], want) << "axis " << a;
      // Padded: the box lies >= padVoxels voxels outside the mesh bounds, centred on them.
      const double pad = settings.padVoxels * double(grid.voxel) - 1e-5 * longest;
      EXPECT_LE(grid.gridMin[a], grid.meshMin[a] - pad);
      EXPECT_GE(grid.gridMax()[a], grid.meshMax[a] + pad);
      EXPECT_NEAR(grid.gridMin[a] + grid.gridMax()[a], grid.meshMin[a] + grid.meshMax[a],
                  1e-5 * longest);
    }
    const int longestAxis = extent.y > extent.x ? 1 : 0;
    EXPECT_EQ(grid.dims[longestAxis], c.intervals + 1 + 2 * settings.padVoxels);
  }
  // buildObjectSdf samples exactly that grid.
  ObjectSdfSettings small;
  small.maxResolution = 20;
  small.padVoxels = 3;
  const TriangleScene mesh = makeBoxMesh(glm::vec3(0.4f, 0.2f, 0.1f), glm::vec4(1.0f));
  const ObjectSdf built = buildObjectSdf(mesh, small), grid = objectGridFor(mesh, small);
  EXPECT_EQ(built.dims, grid.dims);
  EXPECT_EQ(built.gridMin, grid.gridMin);
  EXPECT_EQ(built.voxel, grid.voxel);
  EXPECT_EQ(built.dims.x, 20u + 1 + 6);
}

TEST(ObjectSdf, BadSettingsAreProgrammerErrors) {
  const TriangleScene mesh = makeBoxMesh(glm::vec3(1.0f), glm::vec4(1.0f));
  ObjectSdfSettings s;
  s.minResolution = 65;  // > max
  EXPECT_THROW(objectGridFor(mesh, s), std::invalid_argument);
  s = {};
  s.minResolution = 0;
  EXPECT_THROW(objectGridFor(mesh, s), std::invalid_argument);
  s = {};
  s.targetVoxel = -1;
  EXPECT_THROW(objectGridFor(mesh, s), std::invalid_argument);
  s = {};
  s.targetVoxel = NAN;
  EXPECT_THROW(buildObjectSdf(mesh, s), std::invalid_argument);
}

TEST(ObjectSdf, MaterialsComeFromTheClosestTriangle) {
  // A box whose +x face (triangles 2, 3 of makeBoxMesh) is red and emissive, the rest green.
  const glm::vec3 half(0.5f, 0.4f, 0.3f);
  TriangleScene mesh = makeBoxMesh(half, glm::vec4(0.1f, 0.8f, 0.2f, 1.0f));
  Material red;
  red.baseColorFactor = glm::vec4(0.9f, 0.05f, 0.05f, 1.0f);
  red.emissive = glm::vec3(4.0f, 1.0f, 0.25f);
  mesh.materials.push_back(red);
  mesh.triangleMaterial[2] = mesh.triangleMaterial[3] = 1;
  const ObjectSdf sdf = buildObjectSdf(mesh, test::objectSdfResolution(24));

  const std::uint32_t greenAlbedo = packAlbedo(mesh.materials[0].baseColorFactor);
  const std::uint32_t redAlbedo = packAlbedo(red.baseColorFactor);
  const std::uint32_t redEmission = packRgb9e5(red.emissive);
  ASSERT_NE(greenAlbedo, redAlbedo);
  int redSamples = 0, greenSamples = 0;
  for (std::uint32_t z = 0; z < sdf.dims.z; ++z)
    for (std::uint32_t y = 0; y < sdf.dims.y; ++y)
      for (std::uint32_t x = 0; x < sdf.dims.x; ++x) {
        const glm::dvec3 p(sdf.samplePosition(x, y, z));
        // Distance to each face rectangle; the +x face is index 1 here.
        double d[6];
        for (int axis = 0; axis < 3; ++axis)
          for (int side = 0; side < 2; ++side) {
            glm::dvec3 q = glm::clamp(p, -glm::dvec3(half), glm::dvec3(half));
            q[axis] = side ? half[axis] : -half[axis];
            d[axis * 2 + side] = glm::length(p - q);
          }
        double plusX = d[1], other = INFINITY;
        for (int f = 0; f < 6; ++f)
          if (f != 1) other = std::min(other, d[f]);
        if (std::abs(plusX - other) < 0.1 * sdf.voxel) continue;  // edge tie: either is right
        const std::size_t i = sdf.index(x, y, z);
        if (plusX < other) {
          ++redSamples;
          ASSERT_EQ(sdf.albedo[i], redAlbedo) << x << " " << y << " " << z;
          ASSERT_EQ(sdf.emission[i], redEmission) << x << " " << y << " " << z;
        } else {
          ++greenSamples;
          ASSERT_EQ(sdf.albedo[i], greenAlbedo) << x << " " << y << " " << z;
          ASSERT_EQ(sdf.emission[i], 0u) << x << " " << y << " " << z;
        }
      }
  EXPECT_GT(redSamples, 500);
  EXPECT_GT(greenSamples, 5 * redSamples / 2);
}

TEST(ObjectSdf, DeterministicAndHashedByContent) {
  const TriangleScene mesh = makeSphereMesh(0.5f, glm::vec4(0.3f), 12);
  const ObjectSdf a = buildObjectSdf(mesh, test::objectSdfResolution(24)),
                  b = buildObjectSdf(mesh, test::objectSdfResolution(24));
  EXPECT_EQ(a.distance, b.distance);
  EXPECT_EQ(a.albedo, b.albedo);
  EXPECT_EQ(a.contentHash(), b.contentHash());
  ObjectSdf c = a;
  c.distance[c.sampleCount() / 2] += 0.25f;
  EXPECT_NE(c.contentHash(), a.contentHash());
  c = a;
  c.emission[7] ^= 1u;
  EXPECT_NE(c.contentHash(), a.contentHash());
  c = a;
  c.gridMin.y += 1e-3f;
  EXPECT_NE(c.contentHash(), a.contentHash());
}

TEST(ObjectSdf, BadMeshesThrowInputErrorNamingTheMesh) {
  auto expectKind = [](const TriangleScene& mesh, InputErrorKind kind) {
    try {
      buildObjectSdf(mesh, {});
      ADD_FAILURE() << "no error for " << toString(kind);
    } catch (const InputError& e) {
      EXPECT_EQ(e.kind(), kind) << e.what();
      EXPECT_EQ(e.file(), mesh.source);
      EXPECT_NE(std::string(e.what()).find(mesh.source), std::string::npos);
    }
  };
  TriangleScene empty = makeBoxMesh(glm::vec3(1.0f), glm::vec4(1.0f));
  empty.source = "empty.glb";
  empty.triangles.clear();
  empty.triangleMaterial.clear();
  expectKind(empty, InputErrorKind::Empty);
  TriangleScene nan = makeBoxMesh(glm::vec3(1.0f), glm::vec4(1.0f));
  nan.source = "nan.glb";
  nan.positions[3].y = NAN;
  expectKind(nan, InputErrorKind::NonFinite);
  TriangleScene point = makeBoxMesh(glm::vec3(1.0f), glm::vec4(1.0f));
  point.source = "point.glb";
  for (glm::vec3& p : point.positions) p = glm::vec3(2.0f);
  expectKind(point, InputErrorKind::Empty);
  TriangleScene material = makeBoxMesh(glm::vec3(1.0f), glm::vec4(1.0f));
  material.source = "material.glb";
  material.triangleMaterial[5] = 9;
  expectKind(material, InputErrorKind::OutOfRange);
  TriangleScene vertex = makeBoxMesh(glm::vec3(1.0f), glm::vec4(1.0f));
  vertex.source = "vertex.glb";
  vertex.triangles[0].y = 100;
  expectKind(vertex, InputErrorKind::OutOfRange);
}

// Signed volume by the divergence theorem: positive iff the winding is outward.
double signedVolume(const TriangleScene& m) {
  double v = 0;
  for (const glm::uvec3& t : m.triangles)
    v += glm::dot(glm::dvec3(m.positions[t.x]),
                  glm::cross(glm::dvec3(m.positions[t.y]), glm::dvec3(m.positions[t.z]))) /
         6.0;
  return v;
}

TEST(PrimitiveMeshes, ClosedOutwardAndTheRightSize) {
  const TriangleScene box = makeBoxMesh(glm::vec3(1.0f, 2.0f, 3.0f), glm::vec4(1.0f));
  EXPECT_TRUE(isClosedMesh(box));
  EXPECT_NEAR(signedVolume(box), 48.0, 1e-9);
  EXPECT_EQ(box.boundsMax(), glm::vec3(1.0f, 2.0f, 3.0f));
  for (std::uint32_t segments : {3u, 8u, 24u, 64u}) {
    const TriangleScene sphere = makeSphereMesh(2.0f, glm::vec4(1.0f), segments);
    EXPECT_TRUE(isClosedMesh(sphere)) << segments;
    const double v = signedVolume(sphere), ball = 4.0 / 3.0 * std::numbers::pi * 8.0;
    EXPECT_GT(v, 0.0);
    EXPECT_LT(v, ball);
    if (segments == 64) {
      EXPECT_GT(v, 0.98 * ball);
    }
    for (const glm::vec3& p : sphere.positions) EXPECT_NEAR(glm::length(p), 2.0f, 1e-5f);
  }
  EXPECT_THROW(makeBoxMesh(glm::vec3(1, 0, 1), glm::vec4(1)), std::invalid_argument);
  EXPECT_THROW(makeSphereMesh(-1.0f, glm::vec4(1)), std::invalid_argument);
  EXPECT_THROW(makeSphereMesh(1.0f, glm::vec4(1), 2), std::invalid_argument);
}

}  // namespace
}  // namespace sdfstream
