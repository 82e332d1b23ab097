// Deterministic seeds (bit-identical for any thread count) and the disk cache (a second call
// loads; a corrupted or truncated file is detected and recomputed, never trusted).
#include <cstring>
#include <filesystem>
#include <fstream>
#include <vector>

#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include "reference/irradiance_cache.h"
#include "tests/reference/test_scenes.h"
#include "tests/support/test_data.h"

namespace sdfstream::reference {
namespace {

// A lit room with everything the tracer does: emission, sun through an opening, a point light
// with a shadow caster, sky, bounces.
struct Room {
  TriangleScene scene;
  SceneLights lights;
  test::SurfacePoints points;
  Room() {
    const std::uint32_t grey = test::addMaterial(scene, glm::vec3(0.6f));
    const std::uint32_t red = test::addMaterial(scene, glm::vec3(0.7f, 0.1f, 0.1f));
    const std::uint32_t lamp = test::addMaterial(scene, glm::vec3(0.2f), glm::vec3(4.0f));
    test::addFloor(scene, 3.0f, 0.0f, grey);
    test::addQuad(scene, {-3, 0, -3}, {-3, 3, -3}, {-3, 3, 3}, {-3, 0, 3}, red);   // left wall
    test::addQuad(scene, {-3, 0, -3}, {3, 0, -3}, {3, 3, -3}, {-3, 3, -3}, grey);  // back wall
    test::addFloor(scene, 0.5f, 1.0f, grey);                                       // table top
    test::addQuad(scene, {1, 2.5f, 1}, {2, 2.5f, 1}, {2, 2.5f, 2}, {1, 2.5f, 2}, lamp);
    SceneLight sun;
    sun.direction = glm::normalize(glm::vec3(-1.0f, -2.0f, -0.5f));
    sun.intensity = 2.0f;
    lights.lights.push_back(sun);
    SceneLight point;
    point.type = SceneLight::Type::Point;
    point.position = {0.0, 2.0, 0.0};
    point.intensity = 3.0f;
    lights.lights.push_back(point);
    lights.sky.zenith = glm::vec3(0.3f, 0.5f, 1.0f);
    lights.sky.horizon = glm::vec3(0.6f);
    for (int i = 0; i < 40; ++i) {
      points.positions.push_back({-2.5f + 0.125f * float(i), 0.0f, -2.0f + 0.1f * float(i)});
      points.normals.push_back({0.0f, 1.0f, 0.0f});
    }
  }
};

bool bitIdentical(const std::vector<IrradianceEstimate>& a,
                  const std::vector<IrradianceEstimate>& b) {
  if (a.size() != b.size()) return false;
  for (std::size_t i = 0; i < a.size(); ++i)
    if (std::memcmp(&a[i].mean, &b[i].mean, sizeof(glm::vec3)) != 0 ||
        std::memcmp(&a[i].halfWidth95, &b[i].halfWidth95, sizeof(glm::vec3)) != 0 ||
        a[i].samples != b[i].samples)
      return false;
  return true;
}

TEST(Determinism, SameSeedSameBitsForOneAndTwoThreads) {
  const Room room;
  auto run = [&](int threads, std::uint64_t seed) {
    tbb::task_arena arena(threads);
    std::vector<IrradianceEstimate> e;
    RadianceImage image;
    arena.execute([&] {
      PathTracerSettings settings;
      settings.seed = seed;
      const PathTracer tracer(room.scene, room.lights, settings);
      e = tracer.irradiance(room.points.positions, room.points.normals, 64, IrradianceKind::Total);
      PinholeCamera camera;
      camera.position = {0.0f, 1.5f, 2.9f};
      image = tracer.render(camera, 16, 12, 4, IrradianceKind::Total);
    });
    return std::make_pair(e, image);
  };
  const auto one = run(1, 7), two = run(2, 7), other = run(2, 8);
  EXPECT_TRUE(bitIdentical(one.first, two.first));
  ASSERT_EQ(one.second.pixels.size(), two.second.pixels.size());
  EXPECT_EQ(std::memcmp(one.second.pixels.data(), two.second.pixels.data(),
                        one.second.pixels.size() * sizeof(glm::vec3)),
            0);
  // A different seed must give different numbers (else the seed is ignored).
  EXPECT_FALSE(bitIdentical(one.first, other.first));
  // The room really is lit in several ways (so this test covers the light code too).
  double sum = 0.0;
  for (const auto& e : one.first) sum += e.mean.x;
  EXPECT_GT(sum, 0.0);
}

std::vector<char> readFile(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  return std::vector<char>(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

void writeFile(const std::filesystem::path& p, const std::vector<char>& bytes) {
  std::ofstream out(p, std::ios::binary | std::ios::trunc);
  out.write(bytes.data(), std::streamsize(bytes.size()));
}

TEST(Cache, SecondCallLoadsAndBadFilesAreRecomputed) {
  const Room room;
  const PathTracer tracer(room.scene, room.lights);
  const auto dir = test::scratchDir("reference-cache") / "cache";  // created by the cache
  const auto& pos = room.points.positions;
  const auto& nrm = room.points.normals;
  const std::uint32_t samples = 32;
  const auto kind = IrradianceKind::IndirectOnly;
  const auto path = irradianceCachePath(dir, tracer, pos, nrm, samples, kind);

  CacheOutcome outcome{};
  const auto first = cachedIrradiance(dir, tracer, pos, nrm, samples, kind, &outcome);
  EXPECT_EQ(outcome, CacheOutcome::Computed);
  ASSERT_TRUE(std::filesystem::exists(path));
  EXPECT_EQ(std::filesystem::file_size(path), 40u + 28u * pos.size());
  EXPECT_TRUE(bitIdentical(first, tracer.irradiance(pos, nrm, samples, kind)));

  const auto second = cachedIrradiance(dir, tracer, pos, nrm, samples, kind, &outcome);
  EXPECT_EQ(outcome, CacheOutcome::Loaded);
  EXPECT_TRUE(bitIdentical(first, second));

  // Make the file lie: a plausible-looking but wrong value in the payload.
  std::vector<char> bytes = readFile(path);
  const std::vector<char> good = bytes;
  float poisoned = 1234.5f;
  std::memcpy(bytes.data() + 40, &poisoned, 4);
  writeFile(path, bytes);
  const auto third = cachedIrradiance(dir, tracer, pos, nrm, samples, kind, &outcome);
  EXPECT_EQ(outcome, CacheOutcome::Recomputed);
  EXPECT_TRUE(bitIdentical(first, third));
  EXPECT_EQ(readFile(path), good);  // rewritten

  // Truncated, empty and bad-magic files are recomputed too.
  for (int damage = 0; damage < 3; ++damage) {
    bytes = good;
    if (damage == 0) bytes.resize(bytes.size() - 5);
    if (damage == 1) bytes.clear();
    if (damage == 2) bytes[0] = 'X';
    writeFile(path, bytes);
    const auto again = cachedIrradiance(dir, tracer, pos, nrm, samples, kind, &outcome);
    EXPECT_EQ(outcome, CacheOutcome::Recomputed) << "damage " << damage;
    EXPECT_TRUE(bitIdentical(first, again));
    EXPECT_EQ(readFile(path), good);
  }
  cachedIrradiance(dir, tracer, pos, nrm, samples, kind, &outcome);
  EXPECT_EQ(outcome, CacheOutcome::Loaded);
}

TEST(Cache, KeyCoversEveryInput) {
  Room room;
  const PathTracer tracer(room.scene, room.lights);
  const auto& pos = room.points.positions;
  const auto& nrm = room.points.normals;
  const auto kind = IrradianceKind::Total;
  const std::uint64_t base = irradianceCacheKey(tracer, pos, nrm, 32, kind);
  EXPECT_EQ(base, irradianceCacheKey(tracer, pos, nrm, 32, kind));
  EXPECT_NE(base, irradianceCacheKey(tracer, pos, nrm, 33, kind));
  EXPECT_NE(base, irradianceCacheKey(tracer, pos, nrm, 32, IrradianceKind::IndirectOnly));
  std::vector<glm::vec3> moved = pos;
  moved[3].x += 1e-3f;
  EXPECT_NE(base, irradianceCacheKey(tracer, moved, nrm, 32, kind));
  std::vector<glm::vec3> turned = nrm;
  turned[0] = glm::normalize(glm::vec3(0.1f, 1.0f, 0.0f));
  EXPECT_NE(base, irradianceCacheKey(tracer, pos, turned, 32, kind));
  PathTracerSettings seeded;
  seeded.seed = 99;
  EXPECT_NE(base,
            irradianceCacheKey(PathTracer(room.scene, room.lights, seeded), pos, nrm, 32, kind));
  SceneLights brighter = room.lights;
  brighter.lights[1].intensity *= 2.0f;
  EXPECT_NE(base, irradianceCacheKey(PathTracer(room.scene, brighter), pos, nrm, 32, kind));
  SceneLights bluer = room.lights;
  bluer.sky.zenith.z += 0.1f;
  EXPECT_NE(base, irradianceCacheKey(PathTracer(room.scene, bluer), pos, nrm, 32, kind));
  TriangleScene recoloured = room.scene;
  recoloured.materials[1].baseColorFactor.x = 0.5f;
  EXPECT_NE(base, irradianceCacheKey(PathTracer(recoloured, room.lights), pos, nrm, 32, kind));
  TriangleScene reshaped = room.scene;
  reshaped.positions[0].y -= 0.01f;
  EXPECT_NE(base, irradianceCacheKey(PathTracer(reshaped, room.lights), pos, nrm, 32, kind));
  // Material names and the lights' edit counter do not change the light: same key.
  TriangleScene renamed = room.scene;
  renamed.materials[0].name = "renamed";
  EXPECT_EQ(base, irradianceCacheKey(PathTracer(renamed, room.lights), pos, nrm, 32, kind));
}

}  // namespace
}  // namespace sdfstream::reference
