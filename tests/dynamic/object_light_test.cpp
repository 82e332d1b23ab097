// Moving objects in the light cache: shadow rays see objects, and relighting
// only objectShadowPages after a move gives exactly what relighting everything gives -- so the
// cache is re-lit only where objects moved, and nowhere is stale.
#include <algorithm>

#include <gtest/gtest.h>

#include "gi/gpu_stack_scene.h"
#include "gi/light_cache.h"
#include "gi/object_scene.h"
#include "tests/dynamic/object_scenes.h"
#include "tests/lights/light_scenes.h"
#include "tests/support/analytic_stack.h"
#include "tests/support/gpu_test.h"

namespace sdfstream {
namespace {
namespace gs = gpu_shared;

class ObjectLightTest : public test::GpuTest {};

std::size_t countDifferent(const std::vector<std::uint32_t>& a,
                           const std::vector<std::uint32_t>& b) {
  std::size_t n = 0;
  for (std::size_t i = 0; i < std::min(a.size(), b.size()); ++i) n += a[i] != b[i] ? 1 : 0;
  return n;
}

TEST_F(ObjectLightTest, ShadowsFollowTheObjectAndOnlyItsPagesAreRelit) {
  // A floor (top at y = 40); one cascade, voxel = 1 m.
  test::AnalyticStack stack(
      1, [](glm::vec3 p, float) { return test::sdFloor(p); },
      [](glm::vec3) { return test::uniformMaterial(test::rgba8(200, 200, 200), 0u); });
  const CascadeStackImage& image = stack.image;
  // A sun and a point light beside the object: the relit pages must cover both shadows.
  const std::vector<gs::GpuLight> lights = {test::sunLight({0.4f, 1.0f, 0.2f}, 3.0f),
                                            test::pointLight({40.0f, 60.0f, 60.0f}, 900.0f)};
  gs::GpuSky sky{};
  GpuStackScene scene(ctx());
  scene.uploadAll(image);
  LightCache cache(ctx());
  const std::vector<std::uint32_t> all = lightDirtyPages(nullptr, image, true);
  cache.update(scene, lights, sky, all, image.voxelSize0);
  const std::vector<std::uint32_t> unshadowed = cache.downloadRadiance();

  test::RandomObjects objects;
  ObjectScene objScene(ctx());
  ObjectTransform pose;
  pose.translation = glm::dvec3(64.0, 52.0, 64.0);
  pose.scale = glm::vec3(10.0f, 4.0f / 0.6f, 10.0f / 0.8f);
  const InstanceId box = objects.instances.add(objects.box, pose);
  auto relightChanged = [&](bool full) {
    const auto changed = objects.instances.changedBoxes(objects.library);
    objScene.update(objects.library, objects.instances, image);
    const std::vector<std::uint32_t> pages = full ? all : objectShadowPages(image, changed, lights);
    cache.update(scene, lights, sky, pages, image.voxelSize0, &objScene);
    objects.instances.endFrame();
    return pages.size();
  };
  const std::size_t relit = relightChanged(false);
  const std::vector<std::uint32_t> incremental = cache.downloadRadiance();
  // The same state relit from scratch.
  cache.update(scene, lights, sky, all, image.voxelSize0, &objScene);
  const std::vector<std::uint32_t> full = cache.downloadRadiance();

  // The box's shadows: floor cells that lost more than a fifth of their light (the other light
  // still reaches most of them).
  std::size_t shadowed = 0;
  for (std::size_t i = 0; i < full.size(); ++i) {
    const float before = test::decode(unshadowed[i]).x, after = test::decode(full[i]).x;
    if (before > 0.0f && after < 0.8f * before) ++shadowed;
  }

  // Move the box away: the old shadow must clear (only changed pages relit).
  pose.translation += glm::dvec3(30.0, 0.0, 0.0);
  objects.instances.move(box, pose);
  relightChanged(false);
  const std::vector<std::uint32_t> moved = cache.downloadRadiance();
  cache.update(scene, lights, sky, all, image.voxelSize0, &objScene);
  const std::vector<std::uint32_t> movedFull = cache.downloadRadiance();

  objects.instances.remove(box);
  relightChanged(false);
  const std::vector<std::uint32_t> removed = cache.downloadRadiance();

  std::printf(
      "[figures] light cache with a moving box: %zu shadowed cells; relit %zu of %zu pages "
      "after adding it; incremental vs full relight differ in %zu (added) / %zu (moved) "
      "cells; after removal %zu cells differ from the unshadowed cache\n",
      shadowed, relit, all.size(), countDifferent(incremental, full),
      countDifferent(moved, movedFull), countDifferent(removed, unshadowed));
  EXPECT_GT(shadowed, 50u);
  EXPECT_LT(relit, all.size());
  EXPECT_EQ(countDifferent(incremental, full), 0u);
  EXPECT_EQ(countDifferent(moved, movedFull), 0u);
  EXPECT_EQ(countDifferent(removed, unshadowed), 0u);
}

}  // namespace
}  // namespace sdfstream
