// The two Embree queries the path tracer is built on: closest hit with the barycentrics that
// sampleAlbedo / sampleEmission take (a wrong convention would texture every hit wrongly), and
// the shadow-ray occlusion test with its distance limit.
#include <gtest/gtest.h>

#include "reference/embree_scene.h"
#include "tests/reference/test_scenes.h"

namespace sdfstream {
namespace {

TEST(EmbreeQueries, HitReportsBarycentricsOfVertices1And2) {
  TriangleScene s;
  const std::uint32_t m = test::addMaterial(s, glm::vec3(1.0f));
  s.positions = {{0, 0, 0}, {2, 0, 0}, {0, 0, 2}};
  s.uvs.assign(3, glm::vec2(0.0f));
  s.triangles = {{0, 1, 2}};
  s.triangleMaterial = {m};
  const EmbreeScene embree(s);
  // Straight down onto (0.5, 0, 0.3) = v0 + 0.25·(v1 − v0) + 0.15·(v2 − v0).
  const auto hit = embree.intersect({0.5f, 3.0f, 0.3f}, {0, -1, 0}, 0.0f, 1e30f);
  ASSERT_TRUE(hit);
  EXPECT_NEAR(hit->t, 3.0f, 1e-6f);
  EXPECT_NEAR(hit->bary.x, 0.25f, 1e-6f);
  EXPECT_NEAR(hit->bary.y, 0.15f, 1e-6f);
  EXPECT_EQ(hit->triangle, 0u);
  EXPECT_NEAR(std::abs(hit->normal.y), 1.0f, 1e-6f);
}

TEST(EmbreeQueries, OccludedRespectsTheInterval) {
  TriangleScene s;
  test::addFloor(s, 1.0f, 0.0f, test::addMaterial(s, glm::vec3(1.0f)));
  const EmbreeScene embree(s);
  EXPECT_TRUE(embree.occluded({0, 1, 0}, {0, -1, 0}, 0.0f, 2.0f));
  EXPECT_FALSE(embree.occluded({0, 1, 0}, {0, -1, 0}, 0.0f, 0.99f));  // stops short of the floor
  EXPECT_FALSE(embree.occluded({0, 1, 0}, {0, 1, 0}, 0.0f, 1e30f));   // away from it
  EXPECT_FALSE(embree.occluded({5, 1, 0}, {0, -1, 0}, 0.0f, 1e30f));  // beside it
}

}  // namespace
}  // namespace sdfstream
