// Macro-region object lists (object_regions.comp) against a brute-force OBB-overlap computation
// (every region × every instance, ObjectSceneCpu), for random instance sets including objects
// spanning many regions and objects outside every cascade; plus an
// independent check that needs no shared code: points sampled inside each object's grid box
// must find the object listed in the region that holds them, and in the list of the sub-cell
// that holds them unless the object is one of the region's wide ones.
#include <algorithm>
#include <bit>
#include <random>
#include <set>
#include <string>

#include <gtest/gtest.h>

#include "gi/object_scene.h"
#include "gi/object_scene_cpu.h"
#include "tests/dynamic/object_scenes.h"
#include "tests/support/gpu_test.h"

namespace sdfstream {
namespace {
namespace gs = gpu_shared;

class ObjectRegionsTest : public test::GpuTest {};

std::vector<std::vector<std::uint32_t>> gpuLists(const ObjectScene& scene) {
  const auto regions = scene.downloadRegions();
  const auto list = scene.downloadLists();
  std::vector<std::vector<std::uint32_t>> out(regions.size());
  for (std::size_t r = 0; r < regions.size(); ++r) {
    for (std::uint32_t k = 0; k < regions[r].count; ++k)
      out[r].push_back(list.at(regions[r].start + k).x);
    std::sort(out[r].begin(), out[r].end());
  }
  return out;
}

// The sub-cell lists (object_layout.h): per region the wide count, the occupancy ranks and, for
// every occupied sub-cell, the instances listed there equal the brute-force lists of the CPU
// reference, and the box of the occupied sub-cells equals the one the bits give; the wide entries
// come first in the region list.
// built: the frame has sub-cell lists (else every region is walked with its region list).
void expectSubCellListsEqual(const std::vector<gs::ObjectRegionGpu>& regions,
                             const std::vector<glm::uvec4>& entryData, const ObjectSceneCpu& cpu,
                             bool built) {
  std::size_t wideDiffer = 0, rankDiffer = 0, listsDiffer = 0, withoutLists = 0, subLists = 0,
              subEntries = 0, wideEntries = 0, wideFirst = 0, boundsDiffer = 0;
  for (std::uint32_t r = 0; r < regions.size(); ++r) {
    const gs::ObjectRegionGpu& g = regions[r];
    const gs::ObjectRegionGpu& want = cpu.regions()[r];
    wideDiffer += g.wide != want.wide ? 1 : 0;
    // Host-placed lists put no entry first.
    wideDiffer += !built && g.wide != 0 ? 1 : 0;
    std::uint32_t box = 0;  // the occupied x, y and z as masks
    for (std::uint32_t bit = 0; bit < 512; ++bit)
      if (want.occupancy[bit / 32] >> (bit % 32) & 1u)
        box |= 1u << (bit % 8) | 1u << (8 + bit / 8 % 8) | 1u << (16 + bit / 64);
    boundsDiffer += g.occupiedBounds != box || want.occupiedBounds != box ? 1 : 0;
    if (!built) {  // host-placed lists: no ranks on the GPU (no sub-cell lists to find)
      withoutLists += g.count > 0 ? 1 : 0;
      wideDiffer += g.subBase != gs::kNoSubLists ? 1 : 0;
      continue;
    }
    wideEntries += g.wide;
    // Wide entries first: their instances are the CPU's wide ones (those not in any sub-cell).
    std::set<std::uint32_t> inSubCells;
    for (std::uint32_t w = 0; w < gs::kOccupancyWords / 2; ++w)
      rankDiffer += g.rank[w] != want.rank[w] ? 1 : 0;
    if (g.subBase == gs::kNoSubLists) {
      withoutLists += g.count > g.wide ? 1 : 0;
      continue;
    }
    for (std::uint32_t bit = 0; bit < 512; ++bit) {
      if ((g.occupancy[bit / 32] >> (bit % 32) & 1u) == 0) continue;
      std::uint32_t rank = (g.rank[bit / 64] >> (16 * (bit / 32 % 2))) & 0xffffu;
      rank += std::uint32_t(std::popcount(g.occupancy[bit / 32] & ((1u << (bit % 32)) - 1u)));
      const glm::uvec4 header = entryData.at(g.subBase + rank);
      std::vector<std::uint32_t> got;
      for (std::uint32_t k = 0; k < header.y; ++k) got.push_back(entryData.at(header.x + k).x);
      std::sort(got.begin(), got.end());
      listsDiffer += got != cpu.subCellInstances(r, bit) ? 1 : 0;
      inSubCells.insert(got.begin(), got.end());
      ++subLists;
      subEntries += got.size();
    }
    for (std::uint32_t k = 0; k < g.count; ++k)
      wideFirst += (k < g.wide) == inSubCells.contains(entryData.at(g.start + k).x) ? 1 : 0;
  }
  std::printf(
      "[figures] sub-cell lists: %zu lists, %zu entries, %zu wide entries; %zu regions without "
      "lists; %zu wide counts, %zu rank words, %zu occupied boxes, %zu lists differ; %zu "
      "entries out of order\n",
      subLists, subEntries, wideEntries, withoutLists, wideDiffer, rankDiffer, boundsDiffer,
      listsDiffer, wideFirst);
  if (built) {
    EXPECT_GT(subLists, 0u);
    EXPECT_EQ(withoutLists, 0u) << "the host sizes the sub-cell lists so that they always fit";
  } else {
    EXPECT_EQ(subLists, 0u);
    EXPECT_GT(withoutLists, 0u);
  }
  EXPECT_EQ(wideDiffer, 0u);
  EXPECT_EQ(rankDiffer, 0u);
  EXPECT_EQ(boundsDiffer, 0u);
  EXPECT_EQ(listsDiffer, 0u);
  EXPECT_EQ(wideFirst, 0u);
}

std::size_t expectListsEqual(const CascadeStackImage& stack, test::RandomObjects& objects,
                             const ObjectSceneSettings& settings, gpu::Context& ctx) {
  ObjectScene gpu(ctx, settings);
  gpu.update(objects.library, objects.instances, stack);
  ObjectSceneCpu cpu(objects.library, objects.instances, stack, settings);
  const auto got = gpuLists(gpu);
  const auto& want = cpu.regionInstances();
  EXPECT_EQ(got.size(), want.size());
  if (got.size() != want.size()) return 0;
  std::size_t entries = 0, differing = 0, nonEmpty = 0, spanning = 0;
  std::vector<std::uint32_t> regionsPerInstance(objects.instances.size(), 0);
  for (std::size_t r = 0; r < want.size(); ++r) {
    entries += want[r].size();
    nonEmpty += want[r].empty() ? 0 : 1;
    if (got[r] != want[r]) ++differing;
    for (std::uint32_t i : want[r]) ++regionsPerInstance[i];
  }
  for (std::uint32_t n : regionsPerInstance) spanning += n >= 27 ? 1 : 0;
  const auto regions = gpu.downloadRegions();
  // Each GPU entry's box (16-bit codes over [-0.5, 1.5] region edges from the region's min
  // corner, decoded here from that layout) holds the instance's AABB clipped to that range, and
  // lies within a few codes of it.
  const std::vector<glm::uvec4> entryData = gpu.downloadLists();
  std::size_t looseEntries = 0, uncovered = 0, checked = 0;
  for (std::uint32_t r = 0; r < regions.size(); ++r) {
    const glm::vec4 ro = cpu.frame().frame.regionOrigin[r / gs::kRegionsPerCascade];
    const std::uint32_t local = r % gs::kRegionsPerCascade;
    const glm::vec3 rLo = glm::vec3(ro) + glm::vec3(local % 8, local / 8 % 8, local / 64) * ro.w;
    for (std::uint32_t k = 0; k < regions[r].count; ++k) {
      const glm::uvec4 e = entryData.at(regions[r].start + k);
      ++checked;
      const gs::ObjectInstanceGpu& inst = cpu.frame().instances.at(e.x);
      const std::uint32_t codes[6] = {e.y & 0xffffu, e.y >> 16,     e.z & 0xffffu,
                                      e.z >> 16,     e.w & 0xffffu, e.w >> 16};
      for (int a = 0; a < 3; ++a) {
        const double edge = ro.w, code = edge / 32767.5;
        const double lo = rLo[a] + (codes[a] / 32767.5 - 0.5) * edge;
        const double hi = rLo[a] + (codes[3 + a] / 32767.5 - 0.5) * edge;
        const double wantLo =
            std::clamp(double(inst.boundsMin[a]), rLo[a] - 0.5 * edge, rLo[a] + 1.5 * edge);
        const double wantHi =
            std::clamp(double(inst.boundsMax[a]), rLo[a] - 0.5 * edge, rLo[a] + 1.5 * edge);
        uncovered += lo > wantLo || hi < wantHi ? 1 : 0;
        looseEntries += wantLo - lo > 4.0 * code || hi - wantHi > 4.0 * code ? 1 : 0;
      }
    }
  }
  std::printf(
      "[figures] %zu list entries: %zu axes whose box misses the AABB, %zu looser than 4 "
      "codes\n",
      checked, uncovered, looseEntries);
  EXPECT_EQ(checked, entries);
  EXPECT_EQ(uncovered, 0u);
  EXPECT_EQ(looseEntries, 0u);
  // With sub-cell lists the occupancy holds the instances that are not wide; in host-placed
  // lists every instance (the CPU reference does the same).
  const bool subLists = gpu.frame().subListCapacity > 0;
  std::size_t movedDiffer = 0, occupancyDiffer = 0, occupiedBits = 0;
  for (std::uint32_t r = 0; r < regions.size(); ++r) {
    // The GPU passes keep the host's wake bits as uploaded.
    movedDiffer += regions[r].moved != cpu.regions()[r].moved ? 1 : 0;
    for (std::uint32_t w = 0; w < gs::kOccupancyWords; ++w) {
      movedDiffer += regions[r].wake[w] != cpu.regions()[r].wake[w] ? 1 : 0;
      occupancyDiffer += regions[r].occupancy[w] != cpu.regions()[r].occupancy[w] ? 1 : 0;
      occupiedBits += std::uint32_t(std::popcount(cpu.regions()[r].occupancy[w]));
    }
  }
  std::printf(
      "[figures] %zu instances, %zu regions listed, %zu entries, %zu objects spanning >= 27 "
      "regions: %zu regions differ, %zu moved flags or wake words differ, %zu of %zu occupancy "
      "words differ "
      "(%.1f%% of listed regions' sub-cells occupied)\n",
      objects.instances.size(), nonEmpty, entries, spanning, differing, movedDiffer,
      occupancyDiffer, regions.size() * gs::kOccupancyWords,
      100.0 * double(occupiedBits) / double(std::max<std::size_t>(1, nonEmpty * 512)));
  EXPECT_EQ(differing, 0u);
  EXPECT_EQ(movedDiffer, 0u);
  EXPECT_EQ(occupancyDiffer, 0u);
  EXPECT_GT(occupiedBits, 0u);
  EXPECT_GT(entries, 0u);
  expectSubCellListsEqual(regions, entryData, cpu, subLists);
  return spanning;
}

TEST_F(ObjectRegionsTest, ListsEqualBruteForceObbOverlap) {
  const CascadeStackImage stack = test::windowsOnlyStack(4);
  std::size_t spanning = 0;
  for (std::uint64_t seed : {1u, 2u, 3u}) {
    test::RandomObjects objects;
    objects.addRandom(stack, 300, 30.0 * (1 + seed), seed);
    ObjectSceneSettings settings;
    settings.sizeRule = 0.0f;  // every object in every cascade it overlaps
    settings.subListMinMeanEntries = 0.0f;  // sub-cell lists however short the region lists
    spanning += expectListsEqual(stack, objects, settings, ctx());
  }
  EXPECT_GT(spanning, 0u) << "the scenes must exercise objects spanning many regions";
}

TEST_F(ObjectRegionsTest, SizeRuleDropsSmallObjectsFromCoarseCascadesOnly) {
  const CascadeStackImage stack = test::windowsOnlyStack(4);
  test::RandomObjects objects;
  objects.addRandom(stack, 200, 60.0, 7);
  ObjectSceneSettings settings;
  settings.sizeRule = 4.0f;  // radius below 4 voxels of cascade c: not listed in c
  settings.subListMinMeanEntries = 0.0f;
  expectListsEqual(stack, objects, settings, ctx());
  ObjectSceneCpu cpu(objects.library, objects.instances, stack, settings);
  ObjectSceneSettings all = settings;
  all.sizeRule = 0.0f;
  ObjectSceneCpu every(objects.library, objects.instances, stack, all);
  std::size_t dropped = 0;
  for (std::size_t r = 0; r < cpu.regionInstances().size(); ++r) {
    const bool cascade0 = r < gs::kRegionsPerCascade;
    if (cascade0) {
      EXPECT_EQ(cpu.regionInstances()[r], every.regionInstances()[r]);
    }
    dropped += every.regionInstances()[r].size() - cpu.regionInstances()[r].size();
  }
  EXPECT_GT(dropped, 0u);
}

TEST_F(ObjectRegionsTest, PointsInsideAnObjectFindItListed) {
  const CascadeStackImage stack = test::windowsOnlyStack(3);
  test::RandomObjects objects;
  objects.addRandom(stack, 150, 40.0, 11);
  ObjectSceneSettings settings;
  settings.sizeRule = 0.0f;
  settings.subListMinMeanEntries = 0.0f;
  ObjectScene gpu(ctx(), settings);
  gpu.update(objects.library, objects.instances, stack);
  const auto lists = gpuLists(gpu);
  const auto regions = gpu.downloadRegions();
  const auto& frame = gpu.frame();
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  const std::vector<glm::uvec4> entryData = gpu.downloadLists();
  std::size_t checked = 0, missing = 0, unoccupied = 0, notInSubCell = 0, wideChecked = 0;
  for (std::uint32_t i = 0; i < frame.instances.size(); ++i) {
    const auto& inst = frame.instances[i];
    const glm::vec3 hi = glm::vec3(objects.library.mesh(inst.info.x).dims - 1u);
    for (int k = 0; k < 64; ++k) {
      const glm::vec3 g = hi * glm::vec3(u(rng), u(rng), u(rng));
      const glm::vec3 p(glm::dot(glm::vec3(inst.stackFromGrid[0]), g) + inst.stackFromGrid[0].w,
                        glm::dot(glm::vec3(inst.stackFromGrid[1]), g) + inst.stackFromGrid[1].w,
                        glm::dot(glm::vec3(inst.stackFromGrid[2]), g) + inst.stackFromGrid[2].w);
      for (std::uint32_t c = 0; c < frame.frame.counts.y; ++c) {
        const glm::vec4 ro = frame.frame.regionOrigin[c];
        const glm::vec3 q = (p - glm::vec3(ro)) / ro.w;
        if (glm::any(glm::lessThan(q, glm::vec3(0.01f))) ||
            glm::any(glm::greaterThan(q, glm::vec3(7.99f))))
          continue;
        const glm::ivec3 r(glm::floor(q));
        const std::uint32_t g = c * gs::kRegionsPerCascade + r.x + 8 * (r.y + 8 * r.z);
        const auto& list = lists[g];
        ++checked;
        if (!std::binary_search(list.begin(), list.end(), i)) ++missing;
        // ... and is one of the region's wide instances, or lies in an occupied sub-cell of
        // that region whose sub-cell list holds it.
        const gs::ObjectRegionGpu& region = regions[g];
        bool wide = false;
        for (std::uint32_t k = 0; k < region.wide; ++k)
          wide = wide || entryData.at(region.start + k).x == i;
        if (wide) {
          ++wideChecked;
          continue;
        }
        const glm::ivec3 sc = glm::clamp(glm::ivec3(glm::floor((q - glm::vec3(r)) * 8.0f)),
                                         glm::ivec3(0), glm::ivec3(7));
        const std::uint32_t bit = std::uint32_t(sc.x + 8 * sc.y + 64 * sc.z);
        if (!(region.occupancy[bit / 32] & (1u << (bit % 32)))) {
          ++unoccupied;
          continue;
        }
        std::uint32_t rank = (region.rank[bit / 64] >> (16 * (bit / 32 % 2))) & 0xffffu;
        rank +=
            std::uint32_t(std::popcount(region.occupancy[bit / 32] & ((1u << (bit % 32)) - 1u)));
        const glm::uvec4 header = entryData.at(region.subBase + rank);
        bool listed = false;
        for (std::uint32_t k = 0; k < header.y; ++k)
          listed = listed || entryData.at(header.x + k).x == i;
        if (!listed) ++notInSubCell;
      }
    }
  }
  std::printf(
      "[figures] %zu sampled points inside objects, %zu not listed in their region, %zu of a "
      "wide instance, %zu in an empty sub-cell, %zu not in their sub-cell's list\n",
      checked, missing, wideChecked, unoccupied, notInSubCell);
  EXPECT_GT(checked, 1000u);
  EXPECT_GT(checked, wideChecked + 500u) << "most points must exercise the sub-cell lists";
  EXPECT_EQ(missing, 0u);
  EXPECT_EQ(unoccupied, 0u);
  EXPECT_EQ(notInSubCell, 0u);
}

// Each change's wake ball in stack space, written out here from the rule in ObjectSceneSettings:
// radius r / sqrt(wakeIrradianceChange) around the changed box's centre (lo, hi: its bounding
// cube, which holds the box).
struct WakeBalls {
  std::vector<glm::vec3> lo, hi, centre;
  std::vector<float> reach;
  std::vector<float> halfDiagonal;  // of the changed box: the radius the size rule is applied to
};
WakeBalls wakeBalls(const CascadeStackImage& stack, const std::vector<WorldBox>& changed,
                    float wakeIrradianceChange) {
  WakeBalls w;
  for (const WorldBox& b : changed) {
    const glm::vec3 a = stack.toStack(b.min), z = stack.toStack(b.max);
    const glm::vec3 centre = 0.5f * (a + z);
    const float reach = 0.5f * glm::length(z - a) / std::sqrt(wakeIrradianceChange);
    w.lo.push_back(glm::min(a, centre - reach));
    w.hi.push_back(glm::max(z, centre + reach));
    w.centre.push_back(centre);
    w.reach.push_back(reach);
    w.halfDiagonal.push_back(0.5f * glm::length(z - a));
  }
  return w;
}

// Whether region cascade c lists (and so wakes for) a change of this half-diagonal: cascade 0
// always, coarser ones from sizeRule of their voxels on.
bool wakesIn(const gs::ObjectFrameGpu& frame, std::uint32_t c, float halfDiagonal, float sizeRule) {
  return c == 0 || halfDiagonal >= sizeRule * frame.regionOrigin[c].w / 16.0f;
}

// The wake bits brute force would set: per box, every sub-cell of every region cascade that
// lists its object, within a sub-cell of its wake ball's cube, whose nearest point to the ball's
// centre lies in the ball. A sub-cell within 1e-4 of the ball's radius may go either way (the
// host measures in sub-cell units, row by row). Returns the words that differ from `regions`
// (wake words and moved flags); counts the bits it sets.
std::size_t wakeWordsDifferingFromBruteForce(const gs::ObjectFrameGpu& frame, const WakeBalls& w,
                                             std::span<const gs::ObjectRegionGpu> regions,
                                             float sizeRule, std::size_t& bitsSet) {
  const std::uint32_t cascades = frame.counts.y;
  const std::size_t regionCount = std::size_t(cascades) * gs::kRegionsPerCascade;
  std::vector<gs::ObjectRegionGpu> must(regionCount), may(regionCount);
  for (std::uint32_t c = 0; c < cascades; ++c) {
    const glm::vec4 ro = frame.regionOrigin[c];
    const float sub = ro.w / 8.0f;
    for (std::size_t k = 0; k < w.lo.size(); ++k) {
      if (!wakesIn(frame, c, w.halfDiagonal[k], sizeRule)) continue;
      const glm::ivec3 a =
          glm::max(glm::ivec3(glm::floor((w.lo[k] - glm::vec3(ro)) / sub)) - 1, glm::ivec3(0));
      const glm::ivec3 z =
          glm::min(glm::ivec3(glm::floor((w.hi[k] - glm::vec3(ro)) / sub)) + 1, glm::ivec3(63));
      for (int x = a.x; x <= z.x; ++x)
        for (int y = a.y; y <= z.y; ++y)
          for (int zz = a.z; zz <= z.z; ++zz) {
            const glm::vec3 cLo = glm::vec3(ro) + glm::vec3(x, y, zz) * sub, cHi = cLo + sub;
            const float d = glm::length(glm::clamp(w.centre[k], cLo, cHi) - w.centre[k]);
            if (d > w.reach[k] * (1.0f + 1e-4f)) continue;
            const std::size_t r = c * gs::kRegionsPerCascade + x / 8 + 8 * (y / 8 + 8 * (zz / 8));
            const std::size_t word = y % 8 / 4 + 2 * (zz % 8);
            const std::uint32_t bit = 1u << (8 * (y % 8 % 4) + x % 8);
            may[r].wake[word] |= bit;
            may[r].moved = 1;
            if (d > w.reach[k] * (1.0f - 1e-4f)) continue;
            must[r].wake[word] |= bit;
            must[r].moved = 1;
          }
    }
  }
  std::size_t differ = 0;
  bitsSet = 0;
  for (std::size_t r = 0; r < regionCount; ++r) {
    differ += regions[r].moved < must[r].moved || regions[r].moved > may[r].moved ? 1 : 0;
    for (std::uint32_t i = 0; i < gs::kOccupancyWords; ++i) {
      const std::uint32_t got = regions[r].wake[i];
      differ += (got & ~may[r].wake[i]) != 0u || (must[r].wake[i] & ~got) != 0u ? 1 : 0;
      bitsSet += std::size_t(std::popcount(must[r].wake[i]));
    }
  }
  return differ;
}

// The wake bits against a brute-force computation (every sub-cell of every region cascade
// against every change's wake ball, written out here from the rule in ObjectSceneSettings), on
// a frame with additions, moves and removals; and the rule itself: every point within
// r / sqrt(wakeIrradianceChange) of a changed box's centre wakes, and points far from every
// change do not.
TEST_F(ObjectRegionsTest, WakeBitsEqualBruteForceAndCoverTheWakeDistance) {
  const CascadeStackImage stack = test::windowsOnlyStack(4);
  // Small objects (0.1-0.6 m, voxel 0.25 m) spread over 40 m: their wake balls leave most of
  // the cascades asleep. This frame a third move (a few far), some are removed, some added.
  test::RandomObjects objects;
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const glm::dvec3 centre = stack.cascade0MinWorld + glm::dvec3(64.0 * stack.voxelSize0);
  auto randomPose = [&] {
    ObjectTransform pose;
    pose.translation = centre + 20.0 * glm::dvec3(u(rng), u(rng), u(rng));
    pose.rotation = glm::angleAxis(float(u(rng)) * 3.14159f, glm::normalize(glm::vec3(1, 2, 3)));
    pose.scale = glm::vec3(float(0.35 + 0.25 * u(rng)));
    return pose;
  };
  std::vector<InstanceId> ids;
  for (int k = 0; k < 90; ++k)
    ids.push_back(objects.instances.add(k % 2 ? objects.box : objects.sphere, randomPose()));
  objects.instances.endFrame();
  for (std::size_t k = 0; k < ids.size(); k += 3) {
    ObjectTransform pose = objects.instances.find(ids[k])->pose;
    pose.translation += (k % 7 ? 0.1 : 3.0) * glm::dvec3(u(rng), u(rng), u(rng));
    objects.instances.move(ids[k], pose);
  }
  for (std::size_t k = 1; k < ids.size(); k += 11) objects.instances.remove(ids[k]);
  for (int k = 0; k < 4; ++k) objects.instances.add(objects.box, randomPose());

  ObjectSceneSettings settings;
  settings.wakeIrradianceChange = 0.05f;
  ObjectScene gpu(ctx(), settings);
  gpu.update(objects.library, objects.instances, stack);
  ObjectSceneCpu cpu(objects.library, objects.instances, stack, settings);
  const auto regions = gpu.downloadRegions();
  const auto& frame = cpu.frame();
  const std::vector<WorldBox> changed = objects.instances.changedBounds(objects.library);
  ASSERT_GT(changed.size(), 30u);

  const WakeBalls w = wakeBalls(stack, changed, settings.wakeIrradianceChange);
  std::size_t set = 0;
  const std::size_t differ =
      wakeWordsDifferingFromBruteForce(frame.frame, w, regions, settings.sizeRule, set);
  // The rule: points within each change's wake distance wake in every cascade that holds them
  // and lists an object of its size; points far from every change wake nowhere, nor do points
  // of a cascade whose probes cannot see the object.
  std::uniform_real_distribution<float> unit(-1.0f, 1.0f);
  std::size_t inside = 0, missed = 0, far = 0, falseWakes = 0, unseen = 0, unseenWoken = 0;
  for (std::size_t j = 0; j < w.centre.size(); ++j)
    for (int k = 0; k < 16; ++k) {
      glm::vec3 d(unit(rng), unit(rng), unit(rng));
      const glm::vec3 p = w.centre[j] + d * (w.reach[j] / 1.8f);  // |d| <= sqrt(3) < 1.8
      for (std::uint32_t c = 0; c < frame.frame.counts.y; ++c) {
        const glm::vec4 ro = frame.frame.regionOrigin[c];
        const glm::vec3 q = (p - glm::vec3(ro)) / ro.w;
        if (glm::any(glm::lessThan(q, glm::vec3(0.0f))) ||
            glm::any(glm::greaterThanEqual(q, glm::vec3(8.0f))))
          continue;
        if (!wakesIn(frame.frame, c, w.halfDiagonal[j], settings.sizeRule)) {
          // Woken only if another change's wake cube, in a cascade listing it, reaches p.
          bool other = false;
          for (std::size_t o = 0; o < w.lo.size() && !other; ++o)
            other = wakesIn(frame.frame, c, w.halfDiagonal[o], settings.sizeRule) &&
                    glm::all(glm::greaterThan(p, w.lo[o] - 4.0f * ro.w / 8.0f)) &&
                    glm::all(glm::lessThan(p, w.hi[o] + 4.0f * ro.w / 8.0f));
          if (other) continue;
          ++unseen;
          unseenWoken += cpu.wakes(p, c) ? 1 : 0;
          continue;
        }
        ++inside;
        missed += cpu.wakes(p, c) ? 0 : 1;
      }
    }
  for (int k = 0; k < 4000; ++k) {
    const glm::vec3 p = glm::vec3(64.0f) + 64.0f * glm::vec3(unit(rng), unit(rng), unit(rng));
    bool nearAny = false;
    for (std::size_t j = 0; j < w.lo.size() && !nearAny; ++j)
      nearAny = glm::all(glm::greaterThan(p, w.lo[j] - 4.0f)) &&
                glm::all(glm::lessThan(p, w.hi[j] + 4.0f));
    if (nearAny) continue;
    ++far;
    falseWakes += cpu.wakes(p, 0) ? 1 : 0;
  }
  // The ball, not its cube: points near the cube's corners (1.56 reach from the centre), more
  // than a sub-cell's diagonal outside every ball, stay asleep in cascade 0.
  std::size_t corners = 0, cornerWakes = 0;
  const glm::vec4 ro0 = frame.frame.regionOrigin[0];
  const float subDiagonal0 = std::sqrt(3.0f) * ro0.w / 8.0f;
  for (std::size_t j = 0; j < w.centre.size(); ++j)
    for (int k = 0; k < 8; ++k) {
      const glm::vec3 sign(k & 1 ? 1.0f : -1.0f, k & 2 ? 1.0f : -1.0f, k & 4 ? 1.0f : -1.0f);
      const glm::vec3 p = w.centre[j] + 0.9f * w.reach[j] * sign;
      const glm::vec3 q = (p - glm::vec3(ro0)) / ro0.w;
      if (glm::any(glm::lessThan(q, glm::vec3(0.0f))) ||
          glm::any(glm::greaterThanEqual(q, glm::vec3(8.0f))))
        continue;
      bool clear = true;
      for (std::size_t o = 0; o < w.centre.size() && clear; ++o)
        clear = glm::length(p - w.centre[o]) > w.reach[o] + subDiagonal0;
      if (!clear) continue;
      ++corners;
      cornerWakes += cpu.wakes(p, 0) ? 1 : 0;
    }
  std::printf(
      "[figures] %zu changes: %zu wake sub-cells set, %zu words differ from brute force; %zu "
      "points within wake distance, %zu not woken; %zu points far from every change, %zu woken; "
      "%zu points in cascades not listing the object, %zu woken; %zu points in the wake cubes' "
      "corners outside every ball, %zu woken\n",
      changed.size(), set, differ, inside, missed, far, falseWakes, unseen, unseenWoken, corners,
      cornerWakes);
  EXPECT_EQ(differ, 0u);
  EXPECT_GT(set, 0u);
  EXPECT_GT(inside, 1000u);
  EXPECT_EQ(missed, 0u);
  EXPECT_GT(far, 100u);
  EXPECT_EQ(falseWakes, 0u);
  EXPECT_GT(unseen, 20u);
  EXPECT_EQ(unseenWoken, 0u);
  EXPECT_GT(corners, 20u);
  EXPECT_EQ(cornerWakes, 0u);
}

// Thousands of changes of every size (0.05-4 m; a tenth spread over 240 m, far outside cascade
// 0): the bits, built from rows merged across parallel chunks of boxes, equal brute force in
// every cascade, and the moved-region count is the regions flagged.
TEST(ObjectWakeBits, ManyChangesEqualBruteForce) {
  const CascadeStackImage stack = test::windowsOnlyStack(4);
  test::RandomObjects objects;
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const glm::dvec3 centre = stack.cascade0MinWorld + glm::dvec3(64.0 * stack.voxelSize0);
  std::vector<InstanceId> ids;
  for (int k = 0; k < 3000; ++k) {
    ObjectTransform pose;
    const double spread = k % 10 == 0 ? 120.0 : 20.0;
    pose.translation = centre + spread * glm::dvec3(u(rng), u(rng), u(rng));
    pose.rotation = glm::angleAxis(float(u(rng)) * 3.14159f, glm::normalize(glm::vec3(3, 1, 2)));
    pose.scale = glm::vec3(float(k % 97 == 0 ? 4.0 : 0.3 + 0.25 * u(rng)));
    ids.push_back(objects.instances.add(k % 2 ? objects.box : objects.sphere, pose));
  }
  objects.instances.endFrame();
  for (std::size_t k = 0; k < ids.size(); k += 2) {
    ObjectTransform pose = objects.instances.find(ids[k])->pose;
    pose.translation += 0.5 * glm::dvec3(u(rng), u(rng), u(rng));
    objects.instances.move(ids[k], pose);
  }
  for (std::size_t k = 1; k < ids.size(); k += 9) objects.instances.remove(ids[k]);

  const ObjectSceneSettings settings;
  const ObjectFrameData frame =
      buildObjectFrame(objects.library, objects.instances, stack, settings);
  const WakeBalls w = wakeBalls(stack, frame.changedBoxes, settings.wakeIrradianceChange);
  std::size_t bits = 0;
  const std::size_t differ =
      wakeWordsDifferingFromBruteForce(frame.frame, w, frame.regions, settings.sizeRule, bits);
  std::size_t moved = 0, set = 0;
  for (const gs::ObjectRegionGpu& r : frame.regions) {
    moved += r.moved;
    for (std::uint32_t word : r.wake) set += std::size_t(std::popcount(word));
  }
  // What the balls' bounding cubes (the frame's sub-cell ranges) would have set: the rule before.
  std::size_t cubeBits = 0;
  const std::uint32_t cascades = frame.frame.counts.y;
  for (std::uint32_t c = 0; c < cascades; ++c) {
    std::vector<std::uint64_t> rows(64 * 64, 0);
    for (std::size_t k = 0; k < frame.changedBoxes.size(); ++k) {
      const ObjectFrameData::SubCellRange& r = frame.wakeRanges[k * cascades + c];
      if (r.empty()) continue;
      const std::uint64_t run =
          (~std::uint64_t(0) >> (63 - r.hi.x)) & (~std::uint64_t(0) << r.lo.x);
      for (int z = r.lo.z; z <= r.hi.z; ++z)
        for (int y = r.lo.y; y <= r.hi.y; ++y) rows[std::size_t(y + 64 * z)] |= run;
    }
    for (std::uint64_t row : rows) cubeBits += std::size_t(std::popcount(row));
  }
  std::printf(
      "[figures] %zu changed boxes: %zu wake bits set, %zu words differ from brute force; %u "
      "moved regions; their bounding cubes would set %zu bits (%.2fx)\n",
      frame.changedBoxes.size(), set, differ, frame.movedRegions, cubeBits,
      double(cubeBits) / double(std::max<std::size_t>(set, 1)));
  EXPECT_LT(set, cubeBits);
  EXPECT_GT(frame.changedBoxes.size(), 1500u);
  EXPECT_GT(bits, 10000u);
  EXPECT_LT(bits, frame.regions.size() * 512);  // not everything: the far cascades' edges sleep
  EXPECT_EQ(differ, 0u);
  EXPECT_EQ(moved, frame.movedRegions);
}

// instanceInStack inverts the instance's map from its columns' orthogonality; against the
// general 4×4 products and inverse, on random rotations with non-uniform and mirrored scales
// far from the origin, and its AABB against the 8 transformed corners of the grid box.
TEST(InstanceInStack, EqualsTheGeneralMatrixProductsAndInverse) {
  const CascadeStackImage stack = test::windowsOnlyStack(4);
  test::RandomObjects objects;
  const ObjectSdf& mesh = objects.library.mesh(objects.box);
  std::mt19937 rng(23);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  double worstMap = 0.0, worstInverse = 0.0, worstBounds = 0.0;
  for (int k = 0; k < 500; ++k) {
    ObjectTransform pose;
    pose.translation = glm::dvec3(3000.0 * u(rng), 50.0 * u(rng), 3000.0 * u(rng));
    pose.rotation = glm::angleAxis(
        float(u(rng)) * 3.14159f,
        glm::normalize(glm::vec3(float(u(rng)), float(u(rng)), float(u(rng))) + 1e-3f));
    for (int a = 0; a < 3; ++a)
      pose.scale[a] = float((0.1 + 4.0 * std::abs(u(rng))) * (u(rng) < -0.6 ? -1.0 : 1.0));
    const gs::ObjectInstanceGpu g = instanceInStack(mesh, 0, pose.matrix(), stack);

    glm::dmat4 stackFromWorld(1.0 / stack.voxelSize0);
    stackFromWorld[3] = glm::dvec4(-stack.cascade0MinWorld / stack.voxelSize0, 1.0);
    glm::dmat4 objectFromGrid(double(mesh.voxel));
    objectFromGrid[3] = glm::dvec4(glm::dvec3(mesh.gridMin), 1.0);
    const glm::dmat4 m = stackFromWorld * pose.matrix() * objectFromGrid;
    const glm::dmat4 inverse = glm::inverse(m);
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 4; ++c) {
        // Relative to the row's scale (the translations are thousands of voxels).
        const double mScale = glm::length(glm::dvec3(m[0][r], m[1][r], m[2][r])) + 1.0;
        const double iScale = glm::length(glm::dvec3(inverse[0][r], inverse[1][r], inverse[2][r]));
        worstMap = std::max(worstMap, std::abs(g.stackFromGrid[r][c] - m[c][r]) /
                                          (c == 3 ? std::abs(m[3][r]) + mScale : mScale));
        worstInverse =
            std::max(worstInverse, std::abs(g.gridFromStack[r][c] - inverse[c][r]) /
                                       (c == 3 ? std::abs(inverse[3][r]) + iScale : iScale));
      }
    glm::dvec3 lo(1e300), hi(-1e300);
    for (int n = 0; n < 8; ++n) {
      const glm::dvec3 corner((n & 1) ? mesh.dims.x - 1.0 : 0.0, (n & 2) ? mesh.dims.y - 1.0 : 0.0,
                              (n & 4) ? mesh.dims.z - 1.0 : 0.0);
      const glm::dvec3 p(m * glm::dvec4(corner, 1.0));
      lo = glm::min(lo, p);
      hi = glm::max(hi, p);
    }
    // Relative to the corners' distance from the stack origin: the bounds are stored as floats.
    const double scale = 1.0 + std::max(glm::length(lo), glm::length(hi));
    worstBounds =
        std::max({worstBounds, glm::length(glm::dvec3(glm::vec3(g.boundsMin)) - lo) / scale,
                  glm::length(glm::dvec3(glm::vec3(g.boundsMax)) - hi) / scale});
  }
  std::printf("[figures] 500 poses: worst relative difference map %.2e, inverse %.2e, AABB %.2e\n",
              worstMap, worstInverse, worstBounds);
  EXPECT_LT(worstMap, 1e-6);
  EXPECT_LT(worstInverse, 1e-6);
  EXPECT_LT(worstBounds, 1e-6);
}

// No instances: no pass. Short region lists (a mean below subListMinMeanEntries per occupied
// region): the fill alone, into the slots the host placed, every region walked with its region
// list, and the lists still those of the CPU reference; long enough: all six passes.
TEST_F(ObjectRegionsTest, NoInstancesDispatchesNothingAndShortListsSkipTheSubCellPasses) {
  const CascadeStackImage stack = test::windowsOnlyStack(2);
  test::RandomObjects objects;
  ObjectScene gpu(ctx());
  gpu.update(objects.library, objects.instances, stack);
  EXPECT_FALSE(gpu.active());
  EXPECT_TRUE(gpu.lastTimings().empty());
  objects.addRandom(stack, 60, 20.0, 1);
  gpu.update(objects.library, objects.instances, stack);
  EXPECT_TRUE(gpu.active());
  const ObjectFrameData& frame = gpu.frame();
  ASSERT_GT(frame.occupiedRegions, 0u);
  const double mean = double(frame.listCapacity) / frame.occupiedRegions;
  std::printf("[figures] 60 instances: %u occupied regions, about %.2f entries each\n",
              frame.occupiedRegions, mean);
  auto passes = [](const ObjectScene& scene) {
    std::vector<std::string> names;
    for (const auto& t : scene.lastTimings()) names.push_back(t.name);
    return names;
  };
  const std::vector<std::string> all = {"object_regions_count",   "object_regions_rank",
                                        "object_regions_scan",    "object_regions_subcount",
                                        "object_regions_subscan", "object_regions_fill"};
  ASSERT_EQ(all.size(), std::size_t(ObjectScene::kRegionPasses));
  for (float threshold : {0.0f, 1e6f}) {
    ObjectSceneSettings settings;
    settings.subListMinMeanEntries = threshold;
    ObjectScene scene(ctx(), settings);
    scene.update(objects.library, objects.instances, stack);
    const bool lists = threshold == 0.0f;
    EXPECT_EQ(scene.frame().subListCapacity > 0, lists);
    std::vector<std::string> want = all;
    if (!lists) want = {all[5]};  // the host placed the lists: only the fill
    EXPECT_EQ(passes(scene), want);
    std::size_t without = 0, listed = 0;
    for (const gs::ObjectRegionGpu& r : scene.downloadRegions()) {
      if (r.count == 0) continue;
      ++listed;
      without += r.subBase == gs::kNoSubLists ? 1 : 0;
    }
    EXPECT_GT(listed, 0u);
    EXPECT_EQ(without, lists ? 0u : listed);
    expectListsEqual(stack, objects, settings, ctx());
  }
}

}  // namespace
}  // namespace sdfstream
