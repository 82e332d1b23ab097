// Delta lights and sky against closed forms (light semantics: shaders/shared/light_layout.h and
// reference/path_tracer.h). On an open floor with no sky nothing is reflected back, so the
// irradiance is exactly the direct term and has no variance.
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <vector>

#include <gtest/gtest.h>

#include "reference/path_tracer.h"
#include "shaders/shared/light_layout.h"
#include "tests/reference/test_scenes.h"
#include "tests/support/test_data.h"
#include "world/gltf_import.h"

namespace sdfstream::reference {
namespace {

constexpr float kPi = 3.14159265358979f;
const glm::vec3 kUp(0.0f, 1.0f, 0.0f);

TriangleScene openFloor() {
  TriangleScene s;
  test::addFloor(s, 50.0f, 0.0f, test::addMaterial(s, glm::vec3(0.5f)));
  return s;
}

SceneLight sun(float thetaDegrees, float intensity, glm::vec3 color) {
  SceneLight l;
  l.type = SceneLight::Type::Sun;
  const float t = thetaDegrees * kPi / 180.0f;
  l.direction = -glm::vec3(std::sin(t), std::cos(t), 0.0f);  // the way light travels
  l.intensity = intensity;
  l.color = color;
  return l;
}

SceneLight pointLight(glm::dvec3 position, float intensity) {
  SceneLight l;
  l.type = SceneLight::Type::Point;
  l.position = position;
  l.intensity = intensity;
  return l;
}

void expectRelNear(glm::vec3 actual, glm::vec3 expected, float rel) {
  for (int c = 0; c < 3; ++c)
    EXPECT_NEAR(actual[c], expected[c], rel * std::max(std::abs(expected[c]), 1e-6f))
        << "channel " << c;
}

TEST(DirectLight, SunGivesIntensityTimesCosineAndNoIndirect) {
  const TriangleScene floor = openFloor();
  SceneLights lights;
  const glm::vec3 color(1.0f, 0.5f, 0.25f);
  lights.lights.push_back(sun(35.0f, 3.0f, color));
  const PathTracer tracer(floor, lights);
  const std::vector<glm::vec3> p = {{0, 0, 0}, {10, 0, -7}}, n = {kUp, kUp};
  const auto total = tracer.irradiance(p, n, 64, IrradianceKind::Total);
  for (const auto& e : total) {
    expectRelNear(e.mean, 3.0f * color * std::cos(35.0f * kPi / 180.0f), 1e-5f);
    EXPECT_EQ(e.halfWidth95, glm::vec3(0.0f));
  }
  for (IrradianceKind kind : {IrradianceKind::IndirectOnly, IrradianceKind::NoDirectLights})
    for (const auto& e : tracer.irradiance(p, n, 64, kind)) EXPECT_EQ(e.mean, glm::vec3(0.0f));
  // A surface facing away from the sun gets nothing; one facing it head-on gets I·color.
  const glm::vec3 toSun = -glm::normalize(lights.lights[0].direction);
  const std::vector<glm::vec3> p2 = {{0, 0.5f, 0}, {0, 0.5f, 0}}, n2 = {-toSun, toSun};
  const auto e2 = tracer.irradiance(p2, n2, 16, IrradianceKind::Total);
  // The normal facing away still sees the floor, lit and reflecting: only check the direct term
  // through NoDirectLights' complement.
  const auto e2indirect = tracer.irradiance(p2, n2, 16, IrradianceKind::NoDirectLights);
  expectRelNear(e2[0].mean - e2indirect[0].mean, glm::vec3(0.0f), 1e-5f);
  expectRelNear(e2[1].mean - e2indirect[1].mean, 3.0f * color, 1e-5f);
}

TEST(DirectLight, PointLightFallsOffWithDistanceSquared) {
  const TriangleScene floor = openFloor();
  SceneLights lights;
  lights.lights.push_back(pointLight({0.0, 2.0, 0.0}, 10.0f));
  const PathTracer tracer(floor, lights);
  const std::vector<glm::vec3> p = {{0, 0, 0}, {1.5f, 0, 0}, {0, 0, -4}}, n = {kUp, kUp, kUp};
  const auto e = tracer.irradiance(p, n, 32, IrradianceKind::Total);
  for (std::size_t i = 0; i < p.size(); ++i) {
    const glm::vec3 v = glm::vec3(0, 2, 0) - p[i];
    const float d2 = glm::dot(v, v), cosTheta = v.y / std::sqrt(d2);
    expectRelNear(e[i].mean, glm::vec3(10.0f * cosTheta / d2), 1e-5f);
  }
  // 1.5 m away: d² = 6.25, cos = 0.8 → E = 10·0.8/6.25 = 1.28 (the formula spelled out).
  EXPECT_NEAR(e[1].mean.x, 1.28f, 1e-5f);
}

TEST(DirectLight, OccluderCastsAHardShadowUnlessShadowsAreOff) {
  TriangleScene scene = openFloor();
  // A black square at y = 1 between the light at y = 2 and the floor below it; black so that it
  // reflects nothing back onto the floor.
  test::addFloor(scene, 0.25f, 1.0f, test::addMaterial(scene, glm::vec3(0.0f)));
  SceneLights lights;
  lights.lights.push_back(pointLight({0.0, 2.0, 0.0}, 10.0f));
  const std::vector<glm::vec3> p = {{0, 0, 0}, {0.1f, 0, 0.1f}, {3, 0, 0}}, n = {kUp, kUp, kUp};
  {
    const PathTracer tracer(scene, lights);
    const auto e = tracer.irradiance(p, n, 64, IrradianceKind::Total);
    EXPECT_EQ(e[0].mean, glm::vec3(0.0f));
    EXPECT_EQ(e[1].mean, glm::vec3(0.0f));
    const float d2 = 9.0f + 4.0f;
    expectRelNear(e[2].mean, glm::vec3(10.0f * (2.0f / std::sqrt(d2)) / d2), 1e-5f);
  }
  lights.lights[0].castsShadows = false;
  const PathTracer unshadowed(scene, lights);
  const auto e = unshadowed.irradiance(p, n, 64, IrradianceKind::Total);
  expectRelNear(e[0].mean, glm::vec3(10.0f / 4.0f), 1e-5f);
}

TEST(DirectLight, SpotConeAndRangeWindow) {
  const TriangleScene floor = openFloor();
  SceneLights lights;
  SceneLight spot = pointLight({0.0, 2.0, 0.0}, 8.0f);
  spot.type = SceneLight::Type::Spot;
  spot.direction = glm::vec3(0, -1, 0);
  spot.innerConeDegrees = 20.0f;
  spot.outerConeDegrees = 30.0f;
  lights.lights.push_back(spot);
  const PathTracer tracer(floor, lights);
  auto at = [](float degrees) { return glm::vec3(2.0f * std::tan(degrees * kPi / 180.0f), 0, 0); };
  const std::vector<glm::vec3> p = {at(10.0f), at(25.0f), at(40.0f)}, n = {kUp, kUp, kUp};
  const auto e = tracer.irradiance(p, n, 16, IrradianceKind::Total);
  auto unwindowed = [&](glm::vec3 x) {
    const glm::vec3 v = glm::vec3(0, 2, 0) - x;
    const float d2 = glm::dot(v, v);
    return 8.0f * (v.y / std::sqrt(d2)) / d2;
  };
  expectRelNear(e[0].mean, glm::vec3(unwindowed(p[0])), 1e-5f);
  const float c25 = std::cos(25.0f * kPi / 180.0f), c20 = std::cos(20.0f * kPi / 180.0f),
              c30 = std::cos(30.0f * kPi / 180.0f);
  const float t = (c25 - c30) / (c20 - c30), smooth = t * t * (3.0f - 2.0f * t);
  expectRelNear(e[1].mean, glm::vec3(unwindowed(p[1]) * smooth), 1e-4f);
  EXPECT_GT(smooth, 0.2f);  // the test point really is inside the penumbra
  EXPECT_LT(smooth, 0.8f);
  EXPECT_EQ(e[2].mean, glm::vec3(0.0f));

  // Range window W(d) = clamp(1 − (d/range)⁴, 0, 1)²: d = 2 with range 3 → (1 − 16/81)².
  SceneLights ranged;
  ranged.lights.push_back(pointLight({0.0, 2.0, 0.0}, 8.0f));
  ranged.lights[0].range = 3.0f;
  const PathTracer rangedTracer(floor, ranged);
  const std::vector<glm::vec3> q = {{0, 0, 0}, {3, 0, 0}}, m = {kUp, kUp};
  const auto r = rangedTracer.irradiance(q, m, 16, IrradianceKind::Total);
  const float w = 1.0f - 16.0f / 81.0f;
  expectRelNear(r[0].mean, glm::vec3(8.0f / 4.0f * w * w), 1e-5f);
  EXPECT_EQ(r[1].mean, glm::vec3(0.0f));  // d = √13 > range
}

// Gradient sky over an open floor: ∫ mix(H, Z, cos θ) cos θ dω = π·H + (Z − H)·2π/3.
TEST(DirectLight, GradientSkyIrradiance) {
  const TriangleScene floor = openFloor();
  SceneLights lights;
  lights.sky.horizon = glm::vec3(0.2f, 0.3f, 0.4f);
  lights.sky.zenith = glm::vec3(1.0f, 1.5f, 3.0f);
  const PathTracer tracer(floor, lights);
  const std::vector<glm::vec3> p(8, glm::vec3(0.0f)), n(8, kUp);
  std::vector<glm::vec3> pts = p;
  for (std::size_t i = 0; i < pts.size(); ++i) pts[i].x = float(i);
  const auto e = tracer.irradiance(pts, n, 4096, IrradianceKind::Total);
  const glm::vec3 expected =
      kPi * lights.sky.horizon + (lights.sky.zenith - lights.sky.horizon) * (2.0f * kPi / 3.0f);
  for (const auto& est : e)
    for (int c = 0; c < 3; ++c) {
      EXPECT_NEAR(est.mean[c], expected[c], 0.01f * expected[c]);
      EXPECT_NEAR(est.mean[c], expected[c], 2.0f * est.halfWidth95[c]);
    }
  // Sky seen directly is not indirect light.
  for (const auto& est : tracer.irradiance(pts, n, 64, IrradianceKind::IndirectOnly))
    EXPECT_EQ(est.mean, glm::vec3(0.0f));
  // A uniform sky gives exactly π·L for every cosine-weighted sample.
  lights.sky.zenith = lights.sky.horizon;
  const PathTracer uniform(floor, lights);
  for (const auto& est : uniform.irradiance(pts, n, 64, IrradianceKind::Total)) {
    expectRelNear(est.mean, kPi * lights.sky.horizon, 1e-5f);
  }
}

TEST(DirectLight, TooManyLightsThrow) {
  const TriangleScene floor = openFloor();
  SceneLights lights;
  lights.lights.assign(gpu_shared::kMaxLights + 1, sun(0.0f, 1.0f, glm::vec3(1.0f)));
  EXPECT_THROW(PathTracer(floor, lights), std::invalid_argument);
}

// A glTF scene's own light (KHR_lights_punctual, placed by its node) is what the reference
// lights with when handed TriangleScene::lights: a spot 2 m above a floor, pointing down, gives
// I/d² under it and nothing outside its cone.
TEST(PathTracerDirect, AGltfSceneIsLitByItsOwnSpot) {
  const std::filesystem::path dir = test::scratchDir("ref-gltf-spot");
  const float v[12] = {-20, 0, -20, 20, 0, -20, 20, 0, 20, -20, 0, 20};
  const std::uint16_t idx[6] = {0, 2, 1, 0, 3, 2};
  {
    std::ofstream bin(dir / "floor.bin", std::ios::binary);
    bin.write(reinterpret_cast<const char*>(v), sizeof v);
    bin.write(reinterpret_cast<const char*>(idx), sizeof idx);
  }
  // The spot's node turns -Z (the way a glTF light points) down to -Y: -90 degrees about +X.
  std::ofstream(dir / "lit.gltf") << R"({"asset": {"version": "2.0"},
    "extensionsUsed": ["KHR_lights_punctual"],
    "extensions": {"KHR_lights_punctual": {"lights": [{"type": "spot", "intensity": 8.0,
        "spot": {"innerConeAngle": 0.3, "outerConeAngle": 0.4}}]}},
    "buffers": [{"uri": "floor.bin", "byteLength": 60}],
    "bufferViews": [{"buffer": 0, "byteLength": 48}, {"buffer": 0, "byteOffset": 48, "byteLength": 12}],
    "accessors": [{"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3"},
                  {"bufferView": 1, "componentType": 5123, "count": 6, "type": "SCALAR"}],
    "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1}]}],
    "nodes": [{"mesh": 0}, {"translation": [0, 2, 0], "rotation": [-0.70710678, 0, 0, 0.70710678],
               "extensions": {"KHR_lights_punctual": {"light": 0}}}],
    "scenes": [{"nodes": [0, 1]}]})";
  const TriangleScene scene = loadGltf(dir / "lit.gltf");
  ASSERT_EQ(scene.lights.size(), 1u);
  SceneLights lights;
  lights.lights = scene.lights;
  const PathTracer tracer(scene, lights);
  // Under the spot: d = 2 m, on its axis, facing it: E = I / d^2 (shadow rays leave the floor).
  const glm::vec3 under = tracer.directIrradiance(glm::vec3(0.0f, 0.0f, 0.0f), kUp);
  EXPECT_NEAR(under.g, 8.0f / 4.0f, 0.02f);
  // 3 m to the side the direction from the light is atan(3/2) = 56 degrees off its axis, outside
  // the 23-degree outer cone.
  EXPECT_EQ(tracer.directIrradiance(glm::vec3(3.0f, 0.0f, 0.0f), kUp), glm::vec3(0.0f));
}

}  // namespace
}  // namespace sdfstream::reference
