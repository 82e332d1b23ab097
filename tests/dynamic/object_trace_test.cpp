// The dynamic traversal (objTraceRegions: DDA over macro regions, sphere tracing each listed
// instance's local SDF) against the brute-force nearest hit over all instances, on the GPU and
// as the C++ reference, and against analytic ray-box intersections (the same hit object, |Δt| <=
// 0.5 object voxel).
#include <algorithm>
#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "gi/object_scene.h"
#include "gi/object_scene_cpu.h"
#include "objects/scripted_motion.h"
#include "tests/dynamic/object_scenes.h"
#include "tests/support/gpu_test.h"

namespace sdfstream {
namespace {
namespace gs = gpu_shared;

class ObjectTraceTest : public test::GpuTest {};

std::vector<gs::TraceRay> randomRays(std::uint32_t count, glm::vec3 lo, glm::vec3 hi, float tMax,
                                     std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(0.0f, 1.0f), n(-1.0f, 1.0f);
  std::vector<gs::TraceRay> rays(count);
  for (auto& r : rays) {
    const glm::vec3 o = lo + (hi - lo) * glm::vec3(u(rng), u(rng), u(rng));
    const glm::vec3 d = glm::normalize(glm::vec3(n(rng), n(rng), n(rng)) + 1e-4f);
    r.originTMin = glm::vec4(o, 0.0f);
    r.dirTMax = glm::vec4(d, tMax);
  }
  return rays;
}

// Largest stack-space length of one grid voxel of instance i: "one object voxel" for tolerances.
float objectVoxel(const gs::ObjectInstanceGpu& inst) {
  float v = 0.0f;
  for (int j = 0; j < 3; ++j)
    v = std::max(v, glm::length(glm::vec3(inst.stackFromGrid[0][j], inst.stackFromGrid[1][j],
                                          inst.stackFromGrid[2][j])));
  return v;
}

struct Agreement {
  std::size_t rays = 0, hits = 0, hitMiss = 0, otherObject = 0, farT = 0;
  float worstT = 0.0f;  // in object voxels
};

Agreement compare(std::span<const gs::ObjectTraceHit> a, std::span<const gs::ObjectTraceHit> b,
                  const ObjectFrameData& frame) {
  Agreement g;
  for (std::size_t i = 0; i < a.size(); ++i) {
    ++g.rays;
    const bool ha = a[i].normalT.w >= 0.0f, hb = b[i].normalT.w >= 0.0f;
    if (ha != hb) {
      ++g.hitMiss;
      continue;
    }
    if (!ha) continue;
    ++g.hits;
    const float dt = std::abs(a[i].normalT.w - b[i].normalT.w);
    if (a[i].instance != b[i].instance) {
      // Two surfaces within tolerance of each other (touching objects) is not a disagreement.
      if (dt > 0.5f * objectVoxel(frame.instances[a[i].instance])) ++g.otherObject;
      continue;
    }
    const float inVoxels = dt / objectVoxel(frame.instances[a[i].instance]);
    g.worstT = std::max(g.worstT, inVoxels);
    if (inVoxels > 0.5f) ++g.farT;
  }
  return g;
}

void expectTraversalEqualsBruteForce(gpu::Context& context, std::uint32_t subListEntries,
                                     float subListMinMeanEntries = 0.0f) {
  const CascadeStackImage stack = test::windowsOnlyStack(3);
  test::RandomObjects objects;
  objects.addRandom(stack, 400, 25.0, 21);
  ObjectSceneSettings settings;
  settings.sizeRule = 0.0f;
  settings.maxSubListEntries = subListEntries;
  settings.subListMinMeanEntries = subListMinMeanEntries;
  ObjectScene gpu(context, settings);
  gpu.update(objects.library, objects.instances, stack);
  std::size_t withLists = 0, withoutLists = 0;
  for (const gs::ObjectRegionGpu& r : gpu.downloadRegions()) {
    if (r.count == r.wide) continue;
    (r.subBase == gs::kNoSubLists ? withoutLists : withLists) += 1;
  }
  std::printf(
      "[figures] sub-cell list capacity %u: %zu regions walked with sub-cell lists, %zu "
      "without\n",
      subListEntries, withLists, withoutLists);
  if (subListMinMeanEntries > 0.0f) {  // above this scene's mean: no sub-cell lists at all
    EXPECT_EQ(withLists, 0u);
    EXPECT_GT(withoutLists, 0u);
  } else if (subListEntries == ObjectSceneSettings{}.maxSubListEntries) {
    EXPECT_GT(withLists, 0u);
    EXPECT_EQ(withoutLists, 0u);
  } else {
    EXPECT_GT(withLists, 0u);
    EXPECT_GT(withoutLists, 0u);
  }
  ObjectSceneCpu cpu(objects.library, objects.instances, stack, settings);

  const auto rays = randomRays(4096, glm::vec3(-20.0f), glm::vec3(148.0f), 400.0f, 3);
  const auto regions = gpu.trace(rays, false);
  const double regionMs = gpu.lastTraceTimings().at(0).milliseconds;
  const auto brute = gpu.trace(rays, true);
  const double bruteMs = gpu.lastTraceTimings().at(0).milliseconds;
  std::vector<gs::ObjectTraceHit> cpuBrute(rays.size()), cpuRegions(rays.size());
  for (std::size_t i = 0; i < rays.size(); ++i) {
    cpuBrute[i] = cpu.traceAll(rays[i]);
    cpuRegions[i] = cpu.traceRegions(rays[i]);
  }
  const Agreement gr = compare(regions, brute, gpu.frame());
  const Agreement gc = compare(regions, cpuBrute, gpu.frame());
  const Agreement cc = compare(cpuRegions, cpuBrute, gpu.frame());
  std::uint64_t tried = 0, triedBrute = 0;
  for (std::size_t i = 0; i < rays.size(); ++i) {
    tried += regions[i].tried;
    triedBrute += brute[i].tried;
  }
  std::printf(
      "[figures] %zu rays, %zu hits: regions vs brute force (GPU) %zu hit/miss, %zu other "
      "object, worst |dt| %.3f object voxel; vs CPU brute force %zu / %zu / %.3f; CPU "
      "regions vs CPU brute %zu / %zu / %.3f; instance segments traced %.2f vs %.2f per ray; "
      "GPU %.2f ms vs %.2f ms\n",
      gr.rays, gr.hits, gr.hitMiss, gr.otherObject, gr.worstT, gc.hitMiss, gc.otherObject,
      gc.worstT, cc.hitMiss, cc.otherObject, cc.worstT, double(tried) / rays.size(),
      double(triedBrute) / rays.size(), regionMs, bruteMs);
  EXPECT_GT(gr.hits, rays.size() / 10) << "the rays must hit objects often enough to test";
  for (const Agreement& g : {gr, gc, cc}) {
    EXPECT_LE(g.hitMiss, rays.size() / 1000);  // grazing rays only
    EXPECT_EQ(g.otherObject, 0u);
    EXPECT_EQ(g.farT, 0u);
  }
}

// Also with sub-cell lists too small for the frame (the regions past the capacity are walked
// with their region lists alone, kNoSubLists) and with none at all (region lists shorter than
// subListMinMeanEntries): both must still find the nearest hit.
TEST_F(ObjectTraceTest, RegionTraversalEqualsBruteForceNearestHit) {
  for (std::uint32_t subListEntries : {ObjectSceneSettings{}.maxSubListEntries, 3000u})
    expectTraversalEqualsBruteForce(ctx(), subListEntries);
  expectTraversalEqualsBruteForce(ctx(), ObjectSceneSettings{}.maxSubListEntries, 1e6f);
}
// Exact ray / oriented-box intersection for the box mesh (half extents h) under a pose; also the
// cosine between the ray and the face it enters (world space), to tell grazing rays apart.
struct BoxHit {
  float t = -1.0f;
  float cosine = 0.0f;
};
BoxHit rayBox(glm::dvec3 o, glm::dvec3 d, const glm::dmat4& worldFromObject, glm::dvec3 h) {
  const glm::dmat4 inv = glm::inverse(worldFromObject);
  const glm::dvec3 oo = glm::dvec3(inv * glm::dvec4(o, 1.0));
  const glm::dvec3 dd = glm::dvec3(inv * glm::dvec4(d, 0.0));
  double t0 = -1e300, t1 = 1e300;
  int face = 0;
  for (int a = 0; a < 3; ++a) {
    const double lo = (-h[a] - oo[a]) / dd[a], hi = (h[a] - oo[a]) / dd[a];
    if (std::min(lo, hi) > t0) {
      t0 = std::min(lo, hi);
      face = a;
    }
    t1 = std::min(t1, std::max(lo, hi));
  }
  BoxHit r;
  if (!(t0 <= t1 && t0 > 0)) return r;
  r.t = float(t0);
  // The face normal in world space: the inverse transpose of the linear part.
  glm::dvec3 nObj(0.0);
  nObj[face] = 1.0;
  const glm::dvec3 n = glm::normalize(glm::dvec3(glm::transpose(inv) * glm::dvec4(nObj, 0.0)));
  r.cosine = float(std::abs(glm::dot(n, glm::normalize(d))));
  return r;
}

TEST_F(ObjectTraceTest, HitsRotatedScaledBoxesWhereTheAnalyticIntersectionIs) {
  const CascadeStackImage stack = test::windowsOnlyStack(2);
  test::RandomObjects objects;
  ObjectTransform pose;
  pose.translation = stack.cascade0MinWorld + glm::dvec3(16.0, 16.5, 15.5);
  pose.rotation = glm::angleAxis(0.7f, glm::normalize(glm::vec3(1.0f, 2.0f, 0.5f)));
  pose.scale = glm::vec3(3.0f, 1.5f, 6.0f);
  objects.instances.add(objects.box, pose);
  ObjectScene gpu(ctx());
  gpu.update(objects.library, objects.instances, stack);
  const auto& inst = gpu.frame().instances.at(0);
  const float voxel = objectVoxel(inst);
  // Rays from a shell around the box towards points near its centre.
  std::mt19937 rng(9);
  std::uniform_real_distribution<float> n(-1.0f, 1.0f);
  const glm::vec3 centre = stack.toStack(pose.translation);
  std::vector<gs::TraceRay> rays;
  for (int i = 0; i < 2048; ++i) {
    const glm::vec3 from = centre + 40.0f * glm::normalize(glm::vec3(n(rng), n(rng), n(rng)));
    const glm::vec3 to = centre + 6.0f * glm::vec3(n(rng), n(rng), n(rng));
    gs::TraceRay r;
    r.originTMin = glm::vec4(from, 0.0f);
    r.dirTMax = glm::vec4(glm::normalize(to - from), 200.0f);
    rays.push_back(r);
  }
  const auto hits = gpu.trace(rays, false);
  std::size_t agree = 0, hitMiss = 0, grazing = 0;
  float worst = 0.0f, worstGrazing = 0.0f;
  for (std::size_t i = 0; i < rays.size(); ++i) {
    const glm::dvec3 o =
        stack.cascade0MinWorld + glm::dvec3(glm::vec3(rays[i].originTMin)) * stack.voxelSize0;
    const BoxHit b =
        rayBox(o, glm::dvec3(glm::vec3(rays[i].dirTMax)), pose.matrix(), glm::dvec3(0.5, 0.3, 0.4));
    const float want = b.t < 0 ? -1.0f : float(b.t / stack.voxelSize0);
    if ((want >= 0) != (hits[i].normalT.w >= 0)) {
      ++hitMiss;
      continue;
    }
    if (want < 0) continue;
    const float err = std::abs(hits[i].normalT.w - want) / voxel;
    // Along a grazing ray, a surface error of a fraction of a voxel is a long way in t.
    if (b.cosine < 0.2f) {
      ++grazing;
      worstGrazing = std::max(worstGrazing, err * b.cosine);
      continue;
    }
    ++agree;
    worst = std::max(worst, err);
  }
  std::printf(
      "[figures] rotated non-uniformly scaled box: %zu hits agree, worst |dt| %.3f object "
      "voxel; %zu grazing hits (cos < 0.2), worst |dt|·cos %.3f voxel; %zu hit/miss differ "
      "of %zu rays\n",
      agree, worst, grazing, worstGrazing, hitMiss, rays.size());
  // The sampled SDF rounds the box's edges by a fraction of a voxel (trilinear filtering of the
  // exact distance): rays passing within that of an edge may hit or miss, and hits right at an
  // edge land up to about a voxel late. Traversal against the same SDF is held to 0.5 voxel by
  // RegionTraversalEqualsBruteForceNearestHit; this bounds the SDF's own error.
  EXPECT_GT(agree, 500u);
  EXPECT_LE(hitMiss, rays.size() / 50);
  EXPECT_LE(worst, 1.0f);
  EXPECT_LE(worstGrazing, 0.5f);
}

// Where a ray's walk goes at the stress benchmark's densities (`sdfstream stress`: unit boxes
// and spheres of 0.3-2 m spread over 256 x 16 x 256 m, cascade-0 voxels of 1 m, 4 region
// cascades), counted by the C++ reference: rays start at random points of the objects' layer
// inside cascade 0 in random directions and end at a ground 2 m under the layer (downwards) or
// at 128 voxels, as probe rays bounded by their static hits do. The counts say what a next
// change to the walk must cut (docs/DECISIONS.md); the walk must equal brute force there too.
TEST(ObjectWalkCost, CountsAtTheStressDensitiesAndTheWalkEqualsBruteForce) {
  CascadeStackImage stack = test::windowsOnlyStack(4);
  stack.voxelSize0 = 1.0;
  stack.cascade0MinWorld = glm::dvec3(-64.0);
  const WorldBox layer{glm::dvec3(-128.0, -2.0, -128.0), glm::dvec3(128.0, 14.0, 128.0)};
  std::vector<double> entriesPerRay;
  for (std::uint32_t count : {100u, 1000u, 10000u}) {
    ObjectLibrary library;
    InstanceSet instances;
    spreadObjects(instances, library, count, layer, 1, 2);
    // Counted with the default settings; compared with brute force where every object is listed
    // (the size rule leaves small objects out of the coarser cascades a long ray reaches).
    const ObjectSceneCpu cpu(library, instances, stack);
    ObjectSceneSettings everywhere;
    everywhere.sizeRule = 0.0f;
    const ObjectSceneCpu all(library, instances, stack, everywhere);
    std::mt19937 rng(7);
    std::uniform_real_distribution<float> u(0.0f, 1.0f), n(-1.0f, 1.0f);
    ObjectWalkCounts counts;
    std::size_t occlusionDiffers = 0;  // the shadow rays' any-hit walk against the nearest hit
    std::vector<gs::ObjectTraceHit> walked, brute;
    for (int k = 0; k < 2000; ++k) {
      const glm::vec3 o(4.0f + 120.0f * u(rng), 62.0f + 16.0f * u(rng), 4.0f + 120.0f * u(rng));
      const glm::vec3 d = glm::normalize(glm::vec3(n(rng), n(rng), n(rng)) + 1e-4f);
      const float ground = d.y < 0.0f ? (o.y - 60.0f) / -d.y : 1e30f;
      gs::TraceRay ray{glm::vec4(o, 0.0f), glm::vec4(d, std::min(128.0f, ground))};
      const bool hit = cpu.traceRegions(ray, &counts).normalT.w >= 0.0f;
      occlusionDiffers += cpu.occluded(ray) != hit ? 1 : 0;
      walked.push_back(all.traceRegions(ray));
      brute.push_back(all.traceAll(ray));
    }
    const Agreement g = compare(walked, brute, all.frame());
    const double rays = double(counts.rays);
    std::printf(
        "[figures] %u movers, %llu rays: per ray %.2f region steps, %.2f listed regions, %.2f "
        "crossing occupied sub-cells, %.1f occupancy steps, %.2f sub-cell lists read, %.1f "
        "entries tested, %.2f boxes crossed; %zu hits, %zu hit/miss disagreements, worst |dt| "
        "%.3f object voxel\n",
        count, (unsigned long long)counts.rays, double(counts.regionSteps) / rays,
        double(counts.listedRegions) / rays, double(counts.occupiedRegions) / rays,
        double(counts.occupancySteps) / rays, double(counts.occupiedCells) / rays,
        double(counts.entriesTested) / rays, double(counts.boxesCrossed) / rays, g.hits, g.hitMiss,
        g.worstT);
    EXPECT_EQ(counts.rays, 2000u);
    EXPECT_EQ(occlusionDiffers, 0u) << count;
    EXPECT_EQ(g.hitMiss, 0u) << count;
    EXPECT_EQ(g.otherObject, 0u) << count;
    EXPECT_LE(g.worstT, 0.5f) << count;
    EXPECT_GT(g.hits, 0u) << count;
    EXPECT_LE(counts.occupiedRegions, counts.listedRegions);
    EXPECT_LE(counts.boxesCrossed, counts.entriesTested);
    entriesPerRay.push_back(double(counts.entriesTested) / rays);
  }
  // Denser scenes list more per sub-cell: the tests a ray pays grow with the movers, but only
  // with the objects near the ray (a region list at 10,000 movers made it test 65 entries).
  EXPECT_LT(entriesPerRay[0], entriesPerRay[1]);
  EXPECT_LT(entriesPerRay[1], entriesPerRay[2]);
  EXPECT_LT(entriesPerRay[2], 12.0) << "the walk must test the sub-cells' lists, not the regions'";
}

}  // namespace
}  // namespace sdfstream
