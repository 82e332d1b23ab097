// Moving objects in the demo frames' shading (demo/gi_shading.h, shaders/shade_primary.glsl) on
// the demo_gi scene (floor, red wall, pillar; demo_gi_scene.h):
//  - camera rays that reach an object before the static scene show it, and agree with the CPU
//    reference of the object traversal (ObjectSceneCpu::traceRegions, the same GLSL) on the hit,
//    its distance (within half an object voxel), normal and material; rays whose object lies
//    behind the static hit (here: behind the pillar) keep the static hit;
//  - a hovering object darkens the direct light of the sunlit floor in its shadow to nothing and
//    leaves the floor far from it bit-identical, with GI off (the renderer's own ObjectScene) and
//    on (GiSystem's), which also agree with each other;
//  - with GI, the objects' indirect shadow: under a large hovering box the floor's indirect light
//    (sky light from above) drops, while far from it it stays within a few percent.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "demo/frame_image.h"
#include "demo/gi_shading.h"
#include "gi/object_scene_cpu.h"
#include "tests/demo/demo_gi_scene.h"
#include "tests/support/gpu_test.h"

namespace sdfstream {
namespace {

using test::floorMean;
using test::FloorRegion;
using test::lum;

class DemoGiObjectsTest : public test::GpuTest {};

constexpr ObjectSdfSettings kSdf{16, 24, 0.0, 2};

ObjectTransform pose(glm::dvec3 at, glm::quat rotation = glm::quat(1, 0, 0, 0),
                     glm::vec3 scale = glm::vec3(1.0f)) {
  ObjectTransform t;
  t.translation = at;
  t.rotation = rotation;
  t.scale = scale;
  return t;
}

struct Scene {
  World world = test::demoGiWorld();
  CascadeImage cascade = buildCascade(world, cascadeOriginForWorld(world));
  CascadeStackImage image = stackImageOf(cascade);
};

TEST_F(DemoGiObjectsTest, PrimaryRaysSeeObjectsAsTheCpuTraversalDoes) {
  const Scene s;
  ObjectLibrary library(kSdf);
  const std::uint32_t box = library.addBox({0.3f, 0.2f, 0.25f}, {0.9f, 0.5f, 0.1f, 1.0f});
  const std::uint32_t sphere = library.addSphere(0.3f, {0.2f, 0.4f, 0.9f, 1.0f}, 16);
  InstanceSet instances;
  instances.add(sphere, pose({-0.5, 0.6, 0.5}, glm::quat(1, 0, 0, 0), {1.0f, 1.3f, 1.0f}));
  instances.add(
      box, pose({0.2, 0.45, 1.0}, glm::angleAxis(0.6f, glm::normalize(glm::vec3(0.3f, 1.0f, 0.2f))),
                {1.2f, 0.8f, 1.0f}));
  instances.add(box, pose({-1.1, 1.0, -0.9}, glm::angleAxis(0.9f, glm::vec3(0.0f, 1.0f, 0.0f))));
  // Straight behind the pillar (x 0.8..1.2, z -0.25..0.25, 1.4 m tall) as the camera sees it:
  // only its top shows above the pillar, the rest must stay hidden behind it.
  instances.add(sphere, pose({1.05, 0.9, -0.75}));
  // Resting on the floor: its own contact with the static floor.
  instances.add(box, pose({-0.9, 0.2, 1.3}));

  const SceneLights lights = test::demoGiLights();
  GiRendererOptions options;
  options.gi = true;
  options.settings.probes.raysPerProbe = 16;
  options.settings.probes.spacingBricks = 2;
  GiRenderer renderer(ctx(), options, 1);
  renderer.setObjects(&library, &instances);
  // The CPU reference of this frame's objects (before update() consumes the change record; the
  // traversal does not depend on it).
  const ObjectSceneCpu cpuObjects(library, instances, s.image, options.settings.objects);
  renderer.update(s.image, lights, {}, 0);
  constexpr int kW = 160, kH = 120;
  const ShadedView view = renderer.shade(test::demoGiCamera(), kW, kH, s.image, lights);
  // The static answer of the same rays: the CPU shading reference has no objects.
  const auto statics = shadePrimaryCpu(s.image, view.rays, toGpu(lights.lights, s.image),
                                       toGpu(lights.sky), options.shading, {});

  // Half the finest object voxel, in stack voxels (grid voxel x smallest scale / stack voxel).
  float halfVoxel = 1e30f;
  for (const Instance& i : instances.instances()) {
    const float scale =
        std::min({std::abs(i.pose.scale.x), std::abs(i.pose.scale.y), std::abs(i.pose.scale.z)});
    halfVoxel =
        std::min(halfVoxel, 0.5f * library.mesh(i.mesh).voxel * scale / float(s.image.voxelSize0));
  }
  // Rays whose object and static hits lie within this of each other (stack voxels) may go either
  // way (the object touching the floor).
  const float ambiguous = 0.5f;
  std::size_t objectPixels = 0, hiddenByStatic = 0, missing = 0, extra = 0, tOff = 0, normalOff = 0,
              materialOff = 0;
  for (std::size_t i = 0; i < view.shaded.size(); ++i) {
    const gpu_shared::ShadedHit& g = view.shaded[i];
    const gpu_shared::ObjectTraceHit c = cpuObjects.traceRegions(view.rays[i]);
    const bool staticHit = statics[i].flags & gpu_shared::kHitFlagHit;
    const float tStatic = statics[i].normalT.w, tObject = c.normalT.w;
    const bool gpuObject = g.flags & gpu_shared::kShadeFlagObject;
    if (tObject >= 0.0f && (!staticHit || tObject < tStatic - ambiguous)) {
      if (!gpuObject) {
        ++missing;
        continue;
      }
      ++objectPixels;
      if (std::abs(g.normalT.w - tObject) > halfVoxel) ++tOff;
      if (glm::dot(glm::vec3(g.normalT), glm::vec3(c.normalT)) < 0.99f) ++normalOff;
      if (g.albedo != c.albedo || g.emission != c.emission) ++materialOff;
      if (!(g.flags & gpu_shared::kHitFlagHit) || glm::vec3(g.direct) != glm::vec3(g.direct))
        ++materialOff;  // an object pixel is a hit with finite radiance
    } else if (tObject < 0.0f || (staticHit && tObject > tStatic + ambiguous)) {
      if (tObject >= 0.0f) ++hiddenByStatic;
      if (gpuObject) {
        ++extra;
        continue;
      }
      // No object in front: the static hit, exactly as without objects.
      if (g.flags != statics[i].flags || g.normalT.w != tStatic) ++extra;
    }
  }
  std::printf(
      "%zu object pixels (%zu rays hit an object behind the static scene); missing %zu, extra "
      "%zu, t off %zu (tolerance %.3f voxels), normal off %zu, material off %zu\n",
      objectPixels, hiddenByStatic, missing, extra, tOff, halfVoxel, normalOff, materialOff);
  EXPECT_GT(objectPixels, 300u);
  EXPECT_GT(hiddenByStatic, 20u) << "the sphere behind the pillar should be partly hidden";
  // The same GLSL on both sides: allow a silhouette pixel or two to round the other way.
  EXPECT_LE(missing + extra, 2u);
  EXPECT_LE(tOff, 1u);
  EXPECT_LE(normalOff, 2u);
  EXPECT_EQ(materialOff, 0u);
}

// Mean direct radiance of the floor pixels of r in `view`, and the largest change of the direct
// radiance between two views over the floor pixels of r both see.
struct FloorCompare {
  int pixels = 0;
  double lumA = 0.0, lumB = 0.0;
  float maxChange = 0.0f;
};
FloorCompare compareFloor(const ShadedView& a, const ShadedView& b, const CascadeStackImage& image,
                          FloorRegion r) {
  FloorCompare out;
  for (std::size_t i = 0; i < a.shaded.size(); ++i) {
    if (!test::onFloor(a, image, i, r) || !test::onFloor(b, image, i, r)) continue;
    const glm::vec3 da(a.shaded[i].direct), db(b.shaded[i].direct);
    out.lumA += lum(glm::dvec3(da));
    out.lumB += lum(glm::dvec3(db));
    out.maxChange = std::max(out.maxChange, glm::length(da - db));
    ++out.pixels;
  }
  if (out.pixels) out.lumA /= out.pixels, out.lumB /= out.pixels;
  return out;
}

TEST_F(DemoGiObjectsTest, ObjectShadowDarkensDirectLightOnlyWhereItFalls) {
  const Scene s;
  const SceneLights lights = test::demoGiLights();
  const Camera camera = test::demoGiCamera();
  constexpr int kW = 128, kH = 96;
  // A 0.6 m cube hovering with its centre 0.8 m above the floor: the sun (travelling
  // (-0.5, -1, -0.1)) puts its shadow around (-0.6, 0, 0.82), on sunlit floor the camera sees.
  ObjectLibrary library(kSdf);
  InstanceSet instances;
  instances.add(library.addBox(glm::vec3(0.3f), {0.8f, 0.8f, 0.8f, 1.0f}), pose({-0.2, 0.8, 0.9}));
  const FloorRegion shadow{-0.72f, -0.48f, 0.7f, 0.94f};
  const FloorRegion far{1.3f, 1.9f, 0.5f, 1.5f};

  auto shadeWith = [&](bool gi, bool objects) {
    GiRendererOptions options;
    options.gi = gi;
    options.settings.probes.raysPerProbe = 16;
    options.settings.probes.spacingBricks = 2;
    GiRenderer renderer(ctx(), options, 1);
    if (objects) renderer.setObjects(&library, &instances);
    renderer.update(s.image, lights, {}, 0);
    return renderer.shade(camera, kW, kH, s.image, lights);
  };
  const ShadedView without = shadeWith(false, false);
  const ShadedView withOff = shadeWith(false, true);
  const ShadedView withOn = shadeWith(true, true);

  const FloorCompare under = compareFloor(withOff, without, s.image, shadow);
  const FloorCompare away = compareFloor(withOff, without, s.image, far);
  std::printf(
      "floor in the object's shadow (%d px): direct luminance %.5f with the object, %.5f "
      "without; far away (%d px): %.5f / %.5f, largest change %g\n",
      under.pixels, under.lumA, under.lumB, away.pixels, away.lumA, away.lumB, away.maxChange);
  ASSERT_GT(under.pixels, 10);
  ASSERT_GT(away.pixels, 20);
  EXPECT_GT(under.lumB, 0.3) << "the region is meant to be sunlit without the object";
  EXPECT_LT(under.lumA, 0.02 * under.lumB) << "the object should block the sun there";
  EXPECT_EQ(away.maxChange, 0.0f) << "an object changes nothing far from its shadow";

  // GI on and off shade with the same pass and the same object data.
  std::size_t objectPixels = 0, differ = 0;
  for (std::size_t i = 0; i < withOn.shaded.size(); ++i) {
    objectPixels += (withOn.shaded[i].flags & gpu_shared::kShadeFlagObject) ? 1 : 0;
    if (withOn.shaded[i].flags != withOff.shaded[i].flags ||
        glm::vec3(withOn.shaded[i].direct) != glm::vec3(withOff.shaded[i].direct))
      ++differ;
  }
  std::printf("%zu object pixels; %zu pixels differ between GI on and off\n", objectPixels, differ);
  EXPECT_GT(objectPixels, 30u);
  EXPECT_EQ(differ, 0u);
}

TEST_F(DemoGiObjectsTest, HoveringObjectCastsIndirectShadow) {
  const Scene s;
  // A bright sky: the floor's indirect light comes mostly from above, which the box blocks.
  SceneLights lights = test::demoGiLights();
  lights.sky = SceneSky{glm::vec3(0.5f, 0.6f, 0.8f), glm::vec3(0.5f, 0.6f, 0.8f)};
  const Camera camera = test::demoGiCamera();
  constexpr int kW = 128, kH = 96, kGiFrames = 40;
  ObjectLibrary library(kSdf);
  InstanceSet instances;
  // 1.2 x 0.3 x 1.2 m, 0.35 m above the floor (centre at 0.5 m), in front of the pillar.
  instances.add(library.addBox({0.6f, 0.15f, 0.6f}, {0.7f, 0.7f, 0.7f, 1.0f}),
                pose({-0.4, 0.5, 0.2}));
  // Under its middle (its direct shadow falls elsewhere: the sun is low in -x), seen by the
  // camera below the box's front edge; and far from it.
  const FloorRegion under{-0.75f, -0.05f, 0.55f, 0.8f};
  const FloorRegion far{1.4f, 1.9f, 0.9f, 1.6f};

  probe::ProbeFrameInputs inputs;
  inputs.cameraWorld = camera.position;
  inputs.viewDirection = glm::vec3(glm::normalize(camera.target - camera.position));
  auto render = [&](bool objects, ShadedView* view) {
    GiRendererOptions options;
    options.gi = true;
    options.settings.probes.raysPerProbe = 64;
    options.settings.probes.spacingBricks = 2;
    GiRenderer renderer(ctx(), options, 1);
    if (objects) renderer.setObjects(&library, &instances);
    for (int f = 0; f < kGiFrames; ++f) renderer.update(s.image, lights, inputs, std::uint64_t(f));
    *view = renderer.shade(camera, kW, kH, s.image, lights);
    return renderer.finish(*view);
  };
  ShadedView viewWith, viewWithout;
  const HdrFrame with = render(true, &viewWith);
  const HdrFrame without = render(false, &viewWithout);
  const auto out = test::scratchDir("demo-gi-objects");
  writePng(out / "with.png", toneMap(with.final(), kW, kH, 0.0f));
  writePng(out / "with-indirect.png", toneMap(with.indirect, kW, kH, 0.0f));
  writePng(out / "without-indirect.png", toneMap(without.indirect, kW, kH, 0.0f));
  std::printf("images in %s\n", out.c_str());

  int nUnderWith = 0, nUnderWithout = 0, nFarWith = 0, nFarWithout = 0;
  const double underWith = lum(floorMean(viewWith, s.image, with.indirect, under, &nUnderWith));
  const double underWithout =
      lum(floorMean(viewWithout, s.image, without.indirect, under, &nUnderWithout));
  const double farWith = lum(floorMean(viewWith, s.image, with.indirect, far, &nFarWith));
  const double farWithout =
      lum(floorMean(viewWithout, s.image, without.indirect, far, &nFarWithout));
  std::printf(
      "indirect luminance under the box (%d/%d px): %.4f with, %.4f without; far (%d/%d px): "
      "%.4f / %.4f\n",
      nUnderWith, nUnderWithout, underWith, underWithout, nFarWith, nFarWithout, farWith,
      farWithout);
  ASSERT_GT(nUnderWith, 10);
  ASSERT_GT(nFarWith, 20);
  EXPECT_LT(underWith, 0.8 * underWithout) << "the box should shade the sky light under it";
  EXPECT_NEAR(farWith, farWithout, 0.05 * farWithout) << "and hardly change it far away";
}

}  // namespace
}  // namespace sdfstream
