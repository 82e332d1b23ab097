// Images from the path tracer: inside the white furnace every pixel has the same known radiance;
// looking at the open sky every pixel is the sky.
#include <cmath>

#include <gtest/gtest.h>

#include "reference/path_tracer.h"
#include "tests/reference/test_scenes.h"

namespace sdfstream::reference {
namespace {

const glm::vec3 kLo(-1.0f, 0.0f, -1.0f), kHi(1.0f, 2.0f, 1.0f);
const glm::vec3 kAlbedo(0.5f, 0.4f, 0.6f), kEmission(1.0f, 0.5f, 2.0f);

glm::vec3 meanOf(const RadianceImage& image) {
  glm::dvec3 sum(0.0);
  for (const glm::vec3& p : image.pixels) sum += glm::dvec3(p);
  return glm::vec3(sum / double(image.pixels.size()));
}

// Outgoing radiance in the furnace: Le + ρ/π·E = Le/(1 − ρ) everywhere; its indirect part is
// ρ/π·E_indirect = Le·ρ²/(1 − ρ).
TEST(Render, FurnaceImageIsUniform) {
  const TriangleScene box = test::closedBox(kLo, kHi, kAlbedo, kEmission);
  const PathTracer tracer(box, SceneLights{});
  PinholeCamera camera;
  camera.position = {0.2f, 1.0f, 0.6f};
  camera.forward = {-0.3f, -0.2f, -1.0f};
  camera.verticalFovDegrees = 70.0f;
  const RadianceImage total = tracer.render(camera, 24, 16, 64, IrradianceKind::Total);
  ASSERT_EQ(total.pixels.size(), 24u * 16u);
  const glm::vec3 one(1.0f);
  const glm::vec3 expected = kEmission / (one - kAlbedo);
  const glm::vec3 mean = meanOf(total);
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(mean[c], expected[c], 0.01f * expected[c]);
  const RadianceImage indirect = tracer.render(camera, 24, 16, 64, IrradianceKind::IndirectOnly);
  const glm::vec3 expectedIndirect = kEmission * kAlbedo * kAlbedo / (one - kAlbedo);
  const glm::vec3 meanIndirect = meanOf(indirect);
  for (int c = 0; c < 3; ++c)
    EXPECT_NEAR(meanIndirect[c], expectedIndirect[c], 0.015f * expectedIndirect[c]);

  const auto visible = tracer.visiblePoints(camera, 24, 16);
  ASSERT_EQ(visible.size(), 24u * 16u);
  for (const VisiblePoint& v : visible) {
    ASSERT_TRUE(v.hit);
    EXPECT_LT(glm::dot(v.normal, v.position - camera.position), 0.0f);  // faces the camera
    EXPECT_TRUE(glm::all(glm::greaterThanEqual(v.position, kLo - 1e-4f)));
    EXPECT_TRUE(glm::all(glm::lessThanEqual(v.position, kHi + 1e-4f)));
  }
}

TEST(Render, SkyWhereNothingIsHitAndImageOrientation) {
  TriangleScene scene;
  // One emissive quad filling the lower half of the view (below the horizon, in front).
  test::addQuad(scene, {-100, -1, -100}, {100, -1, -100}, {100, -1, 1}, {-100, -1, 1},
                test::addMaterial(scene, glm::vec3(0.0f), glm::vec3(5.0f)));
  SceneLights lights;
  lights.sky.horizon = glm::vec3(0.25f);
  lights.sky.zenith = glm::vec3(0.25f);  // uniform, so every sky pixel is exactly this
  const PathTracer tracer(scene, lights);
  PinholeCamera camera;  // at the origin looking down -z, up +y
  const RadianceImage image = tracer.render(camera, 8, 8, 4, IrradianceKind::Total);
  // Top row sees the sky, bottom row the emitter (albedo 0: radiance is exactly Le).
  for (int x = 0; x < 8; ++x) {
    EXPECT_EQ(image.pixels[std::size_t(x)], glm::vec3(0.25f));
    EXPECT_EQ(image.pixels[std::size_t(7 * 8 + x)], glm::vec3(5.0f));
  }
  const RadianceImage indirect = tracer.render(camera, 8, 8, 4, IrradianceKind::IndirectOnly);
  for (const glm::vec3& p : indirect.pixels) EXPECT_EQ(p, glm::vec3(0.0f));
}

}  // namespace
}  // namespace sdfstream::reference
